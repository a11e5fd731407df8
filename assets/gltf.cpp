// glTF 2.0 (.gltf and .glb) through tinygltf: the default scene's node tree, its triangle
// primitives and their base-colour materials and textures.
#include <tiny_gltf.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <initializer_list>
#include <map>
#include <string>
#include <utility>
#include <vector>

#include "assets/gltf_schema.h"
#include "assets/model_loading.h"
#include "assets/textures.h"

namespace rigc::loading {
namespace {

namespace fs = std::filesystem;
using Eigen::Vector2f;
using Eigen::Vector3d;
using Eigen::Vector3f;
using ir::Mat4;

// A checked view of an accessor's elements.
struct AccessorView {
  const unsigned char* data = nullptr;
  std::size_t count = 0;
  std::size_t stride = 0;
  int component_type = 0;
  int components = 0;
  bool normalized = false;
};

const char* type_name(int type) {
  switch (type) {
    case TINYGLTF_TYPE_SCALAR:
      return "SCALAR";
    case TINYGLTF_TYPE_VEC2:
      return "VEC2";
    case TINYGLTF_TYPE_VEC3:
      return "VEC3";
    case TINYGLTF_TYPE_VEC4:
      return "VEC4";
    case TINYGLTF_TYPE_MAT2:
      return "MAT2";
    case TINYGLTF_TYPE_MAT3:
      return "MAT3";
    case TINYGLTF_TYPE_MAT4:
      return "MAT4";
    default:
      return "unknown";
  }
}

AccessorView view_accessor(const tinygltf::Model& model, int index, const char* what,
                           int expected_type, std::initializer_list<int> component_types) {
  if (index < 0 || static_cast<std::size_t>(index) >= model.accessors.size()) {
    fail("{} accessor {} does not exist ({} accessors)", what, index, model.accessors.size());
  }
  const tinygltf::Accessor& acc = model.accessors[index];
  if (acc.type != expected_type) {
    fail("accessor {} ({}) has type {}, expected {}", index, what, type_name(acc.type),
         type_name(expected_type));
  }
  if (std::find(component_types.begin(), component_types.end(), acc.componentType) ==
      component_types.end()) {
    fail("accessor {} ({}) has unsupported component type {}", index, what, acc.componentType);
  }
  if (acc.sparse.isSparse) fail("accessor {} ({}) is sparse, which is not supported", index, what);
  AccessorView view;
  view.count = acc.count;
  view.component_type = acc.componentType;
  view.components = tinygltf::GetNumComponentsInType(static_cast<std::uint32_t>(acc.type));
  view.normalized = acc.normalized;
  const int component_size =
      tinygltf::GetComponentSizeInBytes(static_cast<std::uint32_t>(acc.componentType));
  const std::size_t element_size = static_cast<std::size_t>(component_size) * view.components;
  if (acc.count == 0) return view;
  if (acc.bufferView < 0) {
    fail("accessor {} ({}) has no buffer view (zero-filled accessors are not supported)", index,
         what);
  }
  if (static_cast<std::size_t>(acc.bufferView) >= model.bufferViews.size()) {
    fail("accessor {} ({}) uses buffer view {}, which does not exist", index, what, acc.bufferView);
  }
  const tinygltf::BufferView& bv = model.bufferViews[acc.bufferView];
  if (bv.buffer < 0 || static_cast<std::size_t>(bv.buffer) >= model.buffers.size()) {
    fail("buffer view {} uses buffer {}, which does not exist", acc.bufferView, bv.buffer);
  }
  const tinygltf::Buffer& buffer = model.buffers[bv.buffer];
  if (bv.byteOffset > buffer.data.size() || bv.byteLength > buffer.data.size() - bv.byteOffset) {
    fail("buffer view {} (bytes {}..{}) is outside buffer {} ({} bytes)", acc.bufferView,
         bv.byteOffset, bv.byteOffset + bv.byteLength, bv.buffer, buffer.data.size());
  }
  const int stride = acc.ByteStride(bv);
  if (stride <= 0 || static_cast<std::size_t>(stride) < element_size) {
    fail("accessor {} ({}) has an invalid byte stride {}", index, what, bv.byteStride);
  }
  view.stride = static_cast<std::size_t>(stride);
  // Last byte read: byteOffset + stride * (count - 1) + element_size, all within the view.
  const std::size_t length = bv.byteLength;
  if (acc.byteOffset > length || element_size > length - acc.byteOffset ||
      acc.count - 1 > (length - acc.byteOffset - element_size) / view.stride) {
    fail("accessor {} ({}) reads past the end of buffer view {} ({} elements of {} bytes)", index,
         what, acc.bufferView, acc.count, element_size);
  }
  view.data = buffer.data.data() + bv.byteOffset + acc.byteOffset;
  return view;
}

float read_component(const unsigned char* p, int component_type, bool normalized) {
  switch (component_type) {
    case TINYGLTF_COMPONENT_TYPE_FLOAT: {
      float v;
      std::memcpy(&v, p, 4);
      return v;
    }
    case TINYGLTF_COMPONENT_TYPE_BYTE: {
      const auto v = static_cast<float>(static_cast<std::int8_t>(*p));
      return normalized ? std::max(v / 127.0f, -1.0f) : v;
    }
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE: {
      const auto v = static_cast<float>(*p);
      return normalized ? v / 255.0f : v;
    }
    case TINYGLTF_COMPONENT_TYPE_SHORT: {
      std::int16_t s;
      std::memcpy(&s, p, 2);
      const auto v = static_cast<float>(s);
      return normalized ? std::max(v / 32767.0f, -1.0f) : v;
    }
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT: {
      std::uint16_t s;
      std::memcpy(&s, p, 2);
      const auto v = static_cast<float>(s);
      return normalized ? v / 65535.0f : v;
    }
    default:
      return 0.0f;
  }
}

template <int N>
Eigen::Matrix<float, N, 1> read_vec(const AccessorView& view, std::size_t i) {
  Eigen::Matrix<float, N, 1> v = Eigen::Matrix<float, N, 1>::Zero();
  const unsigned char* p = view.data + i * view.stride;
  if (view.component_type == TINYGLTF_COMPONENT_TYPE_FLOAT) {
    std::memcpy(v.data(), p, sizeof(float) * N);
    return v;
  }
  const int size =
      tinygltf::GetComponentSizeInBytes(static_cast<std::uint32_t>(view.component_type));
  for (int k = 0; k < N; ++k) {
    v[k] = read_component(p + k * size, view.component_type, view.normalized);
  }
  return v;
}

std::vector<std::uint32_t> read_indices(const tinygltf::Model& model, int accessor) {
  const AccessorView view =
      view_accessor(model, accessor, "indices", TINYGLTF_TYPE_SCALAR,
                    {TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE, TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT,
                     TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT});
  if (view.count > kMaxTriangles * 3) fail("accessor {} has too many indices", accessor);
  std::vector<std::uint32_t> out(view.count, 0);
  if (view.count == 0) return out;
  const unsigned char* p = view.data;
  switch (view.component_type) {
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE:
      for (std::size_t i = 0; i < view.count; ++i) out[i] = p[i * view.stride];
      break;
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT:
      for (std::size_t i = 0; i < view.count; ++i) {
        std::uint16_t v;
        std::memcpy(&v, p + i * view.stride, 2);
        out[i] = v;
      }
      break;
    default:
      if (view.stride == 4) {
        std::memcpy(out.data(), p, view.count * 4);
      } else {
        for (std::size_t i = 0; i < view.count; ++i) std::memcpy(&out[i], p + i * view.stride, 4);
      }
      break;
  }
  return out;
}

Mat4 node_local_matrix(const tinygltf::Node& node, int index) {
  Mat4 m = Mat4::Identity();
  if (node.matrix.size() == 16) {
    for (int k = 0; k < 16; ++k) m(k % 4, k / 4) = node.matrix[k];  // column-major
  } else {
    if (!node.matrix.empty()) {
      fail("node {} has a matrix with {} values", index, node.matrix.size());
    }
    Eigen::Affine3d t = Eigen::Affine3d::Identity();
    if (!node.translation.empty()) {
      if (node.translation.size() != 3) fail("node {} has a malformed translation", index);
      t.translate(Vector3d(node.translation[0], node.translation[1], node.translation[2]));
    }
    if (!node.rotation.empty()) {
      if (node.rotation.size() != 4) fail("node {} has a malformed rotation", index);
      Eigen::Quaterniond q(node.rotation[3], node.rotation[0], node.rotation[1], node.rotation[2]);
      if (!(q.norm() > 1e-12)) fail("node {} has a zero rotation quaternion", index);
      t.rotate(q.normalized());
    }
    if (!node.scale.empty()) {
      if (node.scale.size() != 3) fail("node {} has a malformed scale", index);
      t.scale(Vector3d(node.scale[0], node.scale[1], node.scale[2]));
    }
    m = t.matrix();
  }
  if (!m.allFinite()) fail("node {} has a transform that is not finite", index);
  return m;
}

// A triangle primitive's vertex attributes; normals and uvs are optional.
struct PrimitiveAttributes {
  AccessorView positions, normals, uvs;
  bool has_normals = false, has_uvs = false;
};

// The corners of the triangles a primitive's indices (or its vertex order) describe, in the
// given triangle mode.
std::vector<std::uint32_t> triangle_corners(std::vector<std::uint32_t> indices, int mode) {
  if (mode == TINYGLTF_MODE_TRIANGLES) return indices;
  std::vector<std::uint32_t> corners;
  if (indices.size() < 3) return corners;
  corners.reserve((indices.size() - 2) * 3);
  for (std::size_t i = 0; i + 2 < indices.size(); ++i) {
    if (mode == TINYGLTF_MODE_TRIANGLE_FAN) {
      corners.insert(corners.end(), {indices[0], indices[i + 1], indices[i + 2]});
    } else if (i % 2 == 0) {
      corners.insert(corners.end(), {indices[i], indices[i + 1], indices[i + 2]});
    } else {
      corners.insert(corners.end(), {indices[i + 1], indices[i], indices[i + 2]});
    }
  }
  return corners;
}

// Renumbers `corners` to the vertices they use, in order of first use; returns the original
// index of each vertex kept.
std::vector<std::uint32_t> compact_vertices(std::size_t vertex_count,
                                            std::vector<std::uint32_t>* corners) {
  std::vector<std::uint32_t> remap(vertex_count, kNone);
  std::vector<std::uint32_t> used;
  used.reserve(std::min(vertex_count, corners->size()));
  for (std::uint32_t& c : *corners) {
    if (remap[c] == kNone) {
      remap[c] = static_cast<std::uint32_t>(used.size());
      used.push_back(c);
    }
    c = remap[c];
  }
  return used;
}

// Converts a model tinygltf has read: its materials, then every mesh its scene's node tree
// places, into one mesh in RigC's +Z-up frame.
class GltfLoader {
 public:
  GltfLoader(const std::string& path, const tinygltf::Model& model, LoadedModel* out)
      : path_(path), model_(model), out_(out), builder_(out) {}

  void run() {
    convert_materials();
    // glTF is +Y up; RigC is +Z up: (x, y, z) -> (x, -z, y).
    Mat4 z_up = Mat4::Zero();
    z_up(0, 0) = 1;
    z_up(1, 2) = -1;
    z_up(2, 1) = 1;
    z_up(3, 3) = 1;
    for (const auto& [node, world] : instances(z_up)) {
      const tinygltf::Node& n = model_.nodes[node];
      if (n.mesh < 0) continue;
      if (static_cast<std::size_t>(n.mesh) >= model_.meshes.size()) {
        fail("node {} uses mesh {}, which does not exist ({} meshes)", node, n.mesh,
             model_.meshes.size());
      }
      add_mesh(n.mesh, world);
    }
    // Meshes without any node (no scenes and no nodes at all) are placed untransformed.
    if (model_.scenes.empty() && model_.nodes.empty()) {
      for (std::size_t i = 0; i < model_.meshes.size(); ++i) add_mesh(static_cast<int>(i), z_up);
    }
    if (out_->mesh.triangles.empty()) {
      if (skipped_primitives_ > 0) {
        fail("contains no triangles (skipped {} primitive(s) of points or lines)",
             skipped_primitives_);
      }
      fail("contains no triangles");
    }
    builder_.finish();
  }

 private:
  // The nodes to draw with their world matrices. The default scene (or the first) is used; a file
  // without scenes uses its root nodes. The hierarchy must be a tree: a node reached twice (a
  // cycle, or a node with two parents) is an error.
  std::vector<std::pair<int, Mat4>> instances(const Mat4& root) {
    std::vector<int> roots;
    if (!model_.scenes.empty()) {
      const int scene = model_.defaultScene >= 0 ? model_.defaultScene : 0;
      if (static_cast<std::size_t>(scene) >= model_.scenes.size()) {
        fail("has no scene with nodes (default scene {} does not exist)", scene);
      }
      roots = model_.scenes[scene].nodes;
      if (roots.empty()) fail("has no scene with nodes (scene {} is empty)", scene);
    } else if (model_.defaultScene >= 0) {
      fail("has no scene with nodes (default scene {} does not exist)", model_.defaultScene);
    } else if (!model_.nodes.empty()) {
      std::vector<char> is_child(model_.nodes.size(), 0);
      for (const tinygltf::Node& n : model_.nodes) {
        for (int c : n.children) {
          if (c >= 0 && static_cast<std::size_t>(c) < is_child.size()) is_child[c] = 1;
        }
      }
      for (std::size_t i = 0; i < model_.nodes.size(); ++i) {
        if (!is_child[i]) roots.push_back(static_cast<int>(i));
      }
      if (roots.empty()) fail("has no scene with nodes (every node is a child: a cycle)");
    } else if (model_.meshes.empty()) {
      fail("has no scene with nodes");
    }
    std::vector<std::pair<int, Mat4>> out;
    std::vector<char> visited(model_.nodes.size(), 0);
    std::vector<std::pair<int, Mat4>> stack;
    for (auto it = roots.rbegin(); it != roots.rend(); ++it) stack.emplace_back(*it, root);
    while (!stack.empty()) {
      auto [node, parent] = std::move(stack.back());
      stack.pop_back();
      if (node < 0 || static_cast<std::size_t>(node) >= model_.nodes.size()) {
        fail("node {} does not exist ({} nodes)", node, model_.nodes.size());
      }
      if (visited[node]) {
        fail("node {} is reached twice: the node hierarchy has a cycle or a shared child", node);
      }
      visited[node] = 1;
      const tinygltf::Node& n = model_.nodes[node];
      const Mat4 world = parent * node_local_matrix(n, node);
      out.emplace_back(node, world);
      for (auto it = n.children.rbegin(); it != n.children.rend(); ++it) {
        stack.emplace_back(*it, world);
      }
    }
    return out;
  }

  void convert_materials() {
    for (std::size_t i = 0; i < model_.materials.size(); ++i) {
      const tinygltf::Material& m = model_.materials[i];
      ir::Material mat;
      mat.name = m.name.empty() ? fmt::format("material{}", i) : m.name;
      const auto& pbr = m.pbrMetallicRoughness;
      Vector3d color(1, 1, 1);
      if (pbr.baseColorFactor.size() >= 3) {
        color = Vector3d(pbr.baseColorFactor[0], pbr.baseColorFactor[1], pbr.baseColorFactor[2]);
      }
      double roughness = pbr.roughnessFactor;
      int texture = pbr.baseColorTexture.index;
      // KHR_materials_pbrSpecularGlossiness: use its diffuse colour and texture.
      if (auto ext = m.extensions.find("KHR_materials_pbrSpecularGlossiness");
          ext != m.extensions.end() && ext->second.IsObject()) {
        const tinygltf::Value& sg = ext->second;
        if (sg.Has("diffuseFactor") && sg.Get("diffuseFactor").IsArray() &&
            sg.Get("diffuseFactor").ArrayLen() >= 3) {
          const tinygltf::Value& f = sg.Get("diffuseFactor");
          color = Vector3d(f.Get(0).GetNumberAsDouble(), f.Get(1).GetNumberAsDouble(),
                           f.Get(2).GetNumberAsDouble());
        }
        if (texture < 0 && sg.Has("diffuseTexture") && sg.Get("diffuseTexture").Has("index")) {
          texture = sg.Get("diffuseTexture").Get("index").GetNumberAsInt();
        }
        if (sg.Has("glossinessFactor")) {
          roughness = 1.0 - sg.Get("glossinessFactor").GetNumberAsDouble();
        }
      }
      if (!color.allFinite() || !std::isfinite(roughness) || !std::isfinite(pbr.metallicFactor)) {
        fail("material {} '{}' has a factor that is not finite", i, m.name);
      }
      mat.base_color = color.cwiseMax(0.0).cwiseMin(1.0);
      mat.roughness = std::clamp(roughness, 0.0, 1.0);
      mat.metallic = std::clamp(pbr.metallicFactor, 0.0, 1.0);
      if (texture >= 0) mat.base_color_texture = convert_texture(texture, static_cast<int>(i));
      out_->materials.push_back(std::move(mat));
    }
  }

  int convert_texture(int texture, int material) {
    if (static_cast<std::size_t>(texture) >= model_.textures.size()) {
      fail("material {} uses texture {}, which does not exist", material, texture);
    }
    const int image = model_.textures[texture].source;
    if (image < 0 || static_cast<std::size_t>(image) >= model_.images.size()) {
      fail("texture {} uses image {}, which does not exist", texture, image);
    }
    if (auto it = image_to_texture_.find(image); it != image_to_texture_.end()) return it->second;
    const tinygltf::Image& img = model_.images[image];
    const bool external = !img.uri.empty() && img.uri.rfind("data:", 0) != 0;
    const std::string what =
        external ? fmt::format("image {} '{}'", image, img.uri) : fmt::format("image {}", image);
    if (img.image.empty() || img.width <= 0 || img.height <= 0) {
      fail("{} could not be loaded (missing file or unsupported format)", what);
    }
    std::string source = external ? (fs::path(path_).parent_path() / img.uri).string()
                                  : fmt::format("{}#image{}", path_, image);
    out_->textures.push_back(make_texture(std::move(source), img.width, img.height, img.component,
                                          img.bits, img.image, what));
    const int index = static_cast<int>(out_->textures.size() - 1);
    image_to_texture_[image] = index;
    return index;
  }

  int default_material() {
    if (default_material_ < 0) {
      ir::Material mat;
      // A primitive without a material: a plain grey dielectric, as Blender's importer and the
      // other formats give it. (glTF's own default is white metal, which photographs almost
      // black under studio lights: no scan is made of that.)
      mat.name = "default";
      mat.base_color = Vector3d(0.8, 0.8, 0.8);
      mat.roughness = 0.8;
      mat.metallic = 0.0;
      out_->materials.push_back(mat);
      default_material_ = static_cast<int>(out_->materials.size() - 1);
    }
    return default_material_;
  }

  void add_mesh(int mesh_index, const Mat4& world) {
    const tinygltf::Mesh& mesh = model_.meshes[mesh_index];
    const Placement placement(world);
    for (std::size_t pi = 0; pi < mesh.primitives.size(); ++pi) {
      add_primitive(mesh, mesh_index, pi, placement);
    }
  }

  void add_primitive(const tinygltf::Mesh& mesh, int mesh_index, std::size_t pi,
                     const Placement& placement) {
    const tinygltf::Primitive& prim = mesh.primitives[pi];
    const int mode = prim.mode < 0 ? TINYGLTF_MODE_TRIANGLES : prim.mode;
    if (mode != TINYGLTF_MODE_TRIANGLES && mode != TINYGLTF_MODE_TRIANGLE_STRIP &&
        mode != TINYGLTF_MODE_TRIANGLE_FAN) {
      ++skipped_primitives_;
      return;
    }
    const PrimitiveAttributes attributes = view_attributes(prim, mesh_index, pi);
    const std::size_t vertex_count = attributes.positions.count;
    std::vector<std::uint32_t> indices = checked_indices(prim, vertex_count);
    if (mode == TINYGLTF_MODE_TRIANGLES && indices.size() % 3 != 0) {
      fail("mesh {} primitive {} has {} indices, not a multiple of 3", mesh_index, pi,
           indices.size());
    }
    std::vector<std::uint32_t> corners = triangle_corners(std::move(indices), mode);
    if (corners.empty()) return;
    const int material = primitive_material(prim, mesh_index, pi);
    // Copy only the vertices the triangles use.
    const std::vector<std::uint32_t> used = compact_vertices(vertex_count, &corners);
    const std::uint32_t base = copy_vertices(mesh, mesh_index, attributes, used, placement);
    builder_.reserve_triangles(corners.size() / 3);
    for (std::size_t i = 0; i < corners.size(); i += 3) {
      builder_.add_triangle(base + corners[i], base + corners[i + 1], base + corners[i + 2],
                            material, placement.flip);
    }
  }

  PrimitiveAttributes view_attributes(const tinygltf::Primitive& prim, int mesh_index,
                                      std::size_t pi) const {
    PrimitiveAttributes a;
    const auto pos_it = prim.attributes.find("POSITION");
    if (pos_it == prim.attributes.end()) {
      fail("mesh {} primitive {} has no POSITION attribute", mesh_index, pi);
    }
    a.positions =
        view_accessor(model_, pos_it->second, "POSITION", TINYGLTF_TYPE_VEC3,
                      {TINYGLTF_COMPONENT_TYPE_FLOAT, TINYGLTF_COMPONENT_TYPE_BYTE,
                       TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE, TINYGLTF_COMPONENT_TYPE_SHORT,
                       TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT});
    const std::size_t vertex_count = a.positions.count;
    if (vertex_count > kMaxVertices) fail("mesh {} has too many vertices", mesh_index);
    if (auto it = prim.attributes.find("NORMAL"); it != prim.attributes.end()) {
      a.normals = view_accessor(model_, it->second, "NORMAL", TINYGLTF_TYPE_VEC3,
                                {TINYGLTF_COMPONENT_TYPE_FLOAT, TINYGLTF_COMPONENT_TYPE_BYTE,
                                 TINYGLTF_COMPONENT_TYPE_SHORT});
      if (a.normals.count != vertex_count) {
        fail("accessor {} (NORMAL) has {} elements but POSITION has {}", it->second,
             a.normals.count, vertex_count);
      }
      a.has_normals = true;
    }
    if (auto it = prim.attributes.find("TEXCOORD_0"); it != prim.attributes.end()) {
      a.uvs = view_accessor(model_, it->second, "TEXCOORD_0", TINYGLTF_TYPE_VEC2,
                            {TINYGLTF_COMPONENT_TYPE_FLOAT, TINYGLTF_COMPONENT_TYPE_BYTE,
                             TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE, TINYGLTF_COMPONENT_TYPE_SHORT,
                             TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT});
      if (a.uvs.count != vertex_count) {
        fail("accessor {} (TEXCOORD_0) has {} elements but POSITION has {}", it->second,
             a.uvs.count, vertex_count);
      }
      a.has_uvs = true;
    }
    return a;
  }

  // The primitive's indices checked against the vertex count, or 0, 1, 2, ... without indices.
  std::vector<std::uint32_t> checked_indices(const tinygltf::Primitive& prim,
                                             std::size_t vertex_count) const {
    std::vector<std::uint32_t> indices;
    if (prim.indices >= 0) {
      indices = read_indices(model_, prim.indices);
      for (std::size_t i = 0; i < indices.size(); ++i) {
        if (indices[i] >= vertex_count) {
          fail("accessor {} index {} is out of range ({} vertices)", prim.indices, indices[i],
               vertex_count);
        }
      }
    } else {
      indices.resize(vertex_count);
      for (std::size_t i = 0; i < vertex_count; ++i) indices[i] = static_cast<std::uint32_t>(i);
    }
    return indices;
  }

  int primitive_material(const tinygltf::Primitive& prim, int mesh_index, std::size_t pi) {
    const int material = prim.material;
    if (material < 0) return default_material();
    if (static_cast<std::size_t>(material) >= model_.materials.size()) {
      fail("mesh {} primitive {} uses material {}, which does not exist", mesh_index, pi, material);
    }
    return material;
  }

  // Appends the vertices `used` lists (original indices), placed in the world; returns the index
  // of the first. A primitive with a missing or broken normal gets all its normals computed.
  std::uint32_t copy_vertices(const tinygltf::Mesh& mesh, int mesh_index,
                              const PrimitiveAttributes& a, const std::vector<std::uint32_t>& used,
                              const Placement& placement) {
    const std::uint32_t base = builder_.add_vertices(used.size());
    bool primitive_normals_ok = a.has_normals && placement.normals_ok;
    for (std::size_t k = 0; k < used.size(); ++k) {
      const std::uint32_t src = used[k];
      const std::uint32_t dst = base + static_cast<std::uint32_t>(k);
      const Vector3f p = read_vec<3>(a.positions, src);
      if (!p.allFinite()) {
        fail("mesh {} '{}' vertex {} has a position that is not finite ({}, {}, {})", mesh_index,
             mesh.name, src, p.x(), p.y(), p.z());
      }
      builder_.position(dst) = placement.linear * p + placement.offset;
      if (primitive_normals_ok) {
        const Vector3f n = placement.to_normal * read_vec<3>(a.normals, src);
        const float len = n.norm();
        if (!std::isfinite(len) || len < 1e-6f) {
          primitive_normals_ok = false;
        } else {
          builder_.normal(dst) = n / len;
        }
      }
      if (a.has_uvs) {
        const Eigen::Vector2f uv = read_vec<2>(a.uvs, src);
        if (uv.allFinite()) builder_.uv(dst) = uv;
      }
    }
    if (!primitive_normals_ok) {
      for (std::size_t k = 0; k < used.size(); ++k) builder_.normal(base + k) = Vector3f::Zero();
      builder_.set_needs_normal(base, used.size());
    }
    if (a.has_uvs) builder_.set_has_uvs();
    return base;
  }

  const std::string& path_;
  const tinygltf::Model& model_;
  LoadedModel* out_;
  MeshBuilder builder_;
  std::map<int, int> image_to_texture_;
  int default_material_ = -1;
  int skipped_primitives_ = 0;
};

}  // namespace

LoadedModel load_gltf(const std::string& path, bool binary) {
  check_gltf_schema(path, binary);
  tinygltf::TinyGLTF loader;
  loader.SetPreserveImageChannels(true);
  tinygltf::Model model;
  std::string err, warn;
  const bool ok = binary ? loader.LoadBinaryFromFile(&model, &err, &warn, path)
                         : loader.LoadASCIIFromFile(&model, &err, &warn, path);
  if (!ok) {
    const std::string message = one_line(err.empty() ? warn : err);
    fail("could not be read: {}", message.empty() ? "unknown error" : message);
  }
  LoadedModel out;
  GltfLoader(path, model, &out).run();
  return out;
}

}  // namespace rigc::loading
