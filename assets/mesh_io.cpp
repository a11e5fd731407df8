#include "assets/mesh_io.h"

#include <assimp/config.h>
#include <assimp/material.h>
#include <assimp/postprocess.h>
#include <assimp/scene.h>
#include <fmt/format.h>
#include <tiny_gltf.h>

#include <algorithm>
#include <array>
#include <assimp/Importer.hpp>
#include <bit>
#include <cctype>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <exception>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <limits>
#include <map>
#include <new>
#include <nlohmann/json.hpp>
#include <optional>
#include <sstream>
#include <stdexcept>
#include <string_view>
#include <system_error>
#include <utility>
#include <vector>

#include "io/atomic_file.h"

namespace rigc {
namespace {

namespace fs = std::filesystem;
using Eigen::Matrix3d;
using Eigen::Vector2f;
using Eigen::Vector3d;
using Eigen::Vector3f;
using ir::Mat4;

constexpr std::uint32_t kNone = std::numeric_limits<std::uint32_t>::max();
// Guards against malformed counts (and absurd instancing) before memory is committed.
constexpr std::size_t kMaxVertices = 200'000'000;
constexpr std::size_t kMaxTriangles = 200'000'000;

// A load failure; the message does not yet name the file.
struct LoadError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

template <typename... Args>
[[noreturn]] void fail(fmt::format_string<Args...> format, Args&&... args) {
  throw LoadError(fmt::format(format, std::forward<Args>(args)...));
}

// Library messages come as several lines; diagnostics want one.
std::string one_line(const std::string& text) {
  std::string out;
  bool pending_sep = false;
  for (char c : text) {
    if (c == '\n' || c == '\r') {
      pending_sep = !out.empty();
      continue;
    }
    if (pending_sep) {
      out += "; ";
      pending_sep = false;
    }
    out += c;
  }
  while (!out.empty() && (out.back() == ' ' || out.back() == ';')) out.pop_back();
  return out;
}

std::string lower(std::string s) {
  for (char& c : s) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return s;
}

// ---------------------------------------------------------------------------------------------
// Building the output mesh.

class Builder {
 public:
  explicit Builder(LoadedModel* model) : model_(model) {}

  // Appends `n` vertices (positions, normals and uvs zeroed); returns the first index.
  std::uint32_t add_vertices(std::size_t n) {
    ir::Mesh& m = model_->mesh;
    const std::size_t base = m.positions.size();
    if (n > kMaxVertices - base) fail("has too many vertices (more than {})", kMaxVertices);
    m.positions.resize(base + n, Vector3f::Zero());
    m.normals.resize(base + n, Vector3f::Zero());
    m.uvs.resize(base + n, Vector2f::Zero());
    needs_normal_.resize(base + n, 0);
    return static_cast<std::uint32_t>(base);
  }

  void reserve_triangles(std::size_t n) {
    ir::Mesh& m = model_->mesh;
    if (n > kMaxTriangles - m.triangles.size()) {
      fail("has too many triangles (more than {})", kMaxTriangles);
    }
    m.triangles.reserve(m.triangles.size() + n);
    m.triangle_material.reserve(m.triangles.size() + n);
  }

  void add_triangle(std::uint32_t a, std::uint32_t b, std::uint32_t c, std::int32_t material,
                    bool flip) {
    ir::Mesh& m = model_->mesh;
    if (m.triangles.size() >= kMaxTriangles) {
      fail("has too many triangles (more than {})", kMaxTriangles);
    }
    if (flip) std::swap(b, c);
    m.triangles.push_back({a, b, c});
    m.triangle_material.push_back(material);
  }

  Vector3f& position(std::uint32_t i) { return model_->mesh.positions[i]; }
  Vector3f& normal(std::uint32_t i) { return model_->mesh.normals[i]; }
  Vector2f& uv(std::uint32_t i) { return model_->mesh.uvs[i]; }
  void set_needs_normal(std::uint32_t first, std::size_t n) {
    std::fill_n(needs_normal_.begin() + first, n, 1);
  }
  void set_has_uvs() { has_uvs_ = true; }

  // Checks the result, computes the normals the file did not give (area-weighted) and normalises.
  void finish() {
    ir::Mesh& m = model_->mesh;
    if (m.triangles.empty()) fail("contains no triangles");
    for (std::size_t i = 0; i < m.positions.size(); ++i) {
      if (!m.positions[i].allFinite()) fail("vertex {} has a position that is not finite", i);
    }
    // A mesh of lines and points only has no surface to see or measure: it rendered nothing,
    // coverage printed -nan, and eval's surface sampler threw.
    const bool any_area = std::any_of(m.triangles.begin(), m.triangles.end(), [&](const auto& t) {
      const Eigen::Vector3d p0 = m.positions[t[0]].template cast<double>();
      const Eigen::Vector3d e1 = m.positions[t[1]].template cast<double>() - p0;
      const Eigen::Vector3d e2 = m.positions[t[2]].template cast<double>() - p0;
      return e1.cross(e2).squaredNorm() > 0;
    });
    if (!any_area)
      fail("has no triangle with an area (all {} are lines or points)", m.triangles.size());
    const bool any_missing =
        std::find(needs_normal_.begin(), needs_normal_.end(), 1) != needs_normal_.end();
    if (any_missing) {
      for (const auto& t : m.triangles) {
        if (!needs_normal_[t[0]] && !needs_normal_[t[1]] && !needs_normal_[t[2]]) continue;
        const Vector3f& p0 = m.positions[t[0]];
        const Vector3f n = (m.positions[t[1]] - p0).cross(m.positions[t[2]] - p0);
        for (std::uint32_t v : t) {
          if (needs_normal_[v]) m.normals[v] += n;
        }
      }
    }
    for (Vector3f& n : m.normals) {
      const float len = n.norm();
      n = (len > 0 && std::isfinite(len)) ? Vector3f(n / len) : Vector3f(0, 0, 1);
    }
    if (!has_uvs_) m.uvs.clear();
    for (std::int32_t material : m.triangle_material) {
      if (material < 0 || static_cast<std::size_t>(material) >= model_->materials.size()) {
        fail("internal error: material index {} out of range", material);
      }
    }
  }

 private:
  LoadedModel* model_;
  std::vector<std::uint8_t> needs_normal_;
  bool has_uvs_ = false;
};

Matrix3d normal_matrix(const Matrix3d& linear, bool* ok) {
  const double det = linear.determinant();
  *ok = std::isfinite(det) && std::abs(det) > 1e-300;
  if (!*ok) return Matrix3d::Identity();
  return linear.inverse().transpose();
}

// Converts decoded pixels (8 or 16 bits per channel) to an 8-bit ir::Texture.
ir::Texture make_texture(std::string source, int width, int height, int channels, int bits,
                         const std::vector<unsigned char>& data, const std::string& what) {
  if (width <= 0 || height <= 0 || channels < 1 || channels > 4 || (bits != 8 && bits != 16)) {
    fail("{} has an unsupported pixel format ({}x{}, {} channels, {} bits)", what, width, height,
         channels, bits);
  }
  const std::size_t n = static_cast<std::size_t>(width) * height * channels;
  if (data.size() != n * (bits / 8)) fail("{} has truncated pixel data", what);
  ir::Texture tex;
  tex.source = std::move(source);
  tex.width = width;
  tex.height = height;
  tex.channels = channels;
  if (bits == 8) {
    tex.pixels.assign(data.begin(), data.end());
  } else {
    tex.pixels.resize(n);
    for (std::size_t i = 0; i < n; ++i) {
      std::uint16_t v;
      std::memcpy(&v, data.data() + 2 * i, 2);
      tex.pixels[i] = static_cast<std::uint8_t>((v + 128U) / 257U);
    }
  }
  return tex;
}

std::vector<unsigned char> read_file_bytes(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) fail("cannot open '{}'", path.string());
  in.seekg(0, std::ios::end);
  const std::streamoff size = in.tellg();
  if (size < 0) fail("cannot read '{}'", path.string());
  in.seekg(0, std::ios::beg);
  std::vector<unsigned char> bytes(static_cast<std::size_t>(size));
  if (size > 0 && !in.read(reinterpret_cast<char*>(bytes.data()), size)) {
    fail("cannot read '{}'", path.string());
  }
  return bytes;
}

// A PNG's size, channels and bit depth from its header (IHDR, which the format puts first), or
// nothing if `bytes` is no PNG or the header is broken. Read only to explain a decoding failure:
// stb_image refuses a PNG too large for it, and tinygltf reports every failure alike.
struct PngHeader {
  std::uint32_t width = 0, height = 0;
  int channels = 0;
  int bits = 0;
};
std::optional<PngHeader> png_header(const std::vector<unsigned char>& bytes) {
  static constexpr unsigned char kSignature[8] = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1A, '\n'};
  if (bytes.size() < 33 || !std::equal(kSignature, kSignature + 8, bytes.begin()) ||
      std::string_view(reinterpret_cast<const char*>(bytes.data()) + 8, 8) !=
          std::string_view("\0\0\0\x0dIHDR", 8)) {
    return std::nullopt;
  }
  const auto big_endian = [&](std::size_t at) {
    return std::uint32_t{bytes[at]} << 24 | std::uint32_t{bytes[at + 1]} << 16 |
           std::uint32_t{bytes[at + 2]} << 8 | std::uint32_t{bytes[at + 3]};
  };
  PngHeader header{big_endian(16), big_endian(20), 0, bytes[24]};
  if (header.bits != 1 && header.bits != 2 && header.bits != 4 && header.bits != 8 &&
      header.bits != 16) {
    return std::nullopt;
  }
  // Channels by colour type (grey, -, RGB, palette, grey + alpha, -, RGBA); a palette counts as
  // 4, as stb_image counts it.
  static constexpr int kChannels[7] = {1, 0, 3, 4, 2, 0, 4};
  if (bytes[25] >= 7 || kChannels[bytes[25]] == 0) return std::nullopt;
  header.channels = kChannels[bytes[25]];
  return header;
}

// Decodes an encoded image (PNG, JPEG, ...) with the stb_image inside tinygltf.
ir::Texture decode_image(std::string source, const std::vector<unsigned char>& bytes,
                         const std::string& what) {
  if (bytes.empty() || bytes.size() > static_cast<std::size_t>(std::numeric_limits<int>::max())) {
    fail("{} is empty or too large", what);
  }
  tinygltf::Image image;
  std::string err, warn;
  if (!tinygltf::LoadImageData(&image, 0, &err, &warn, 0, 0, bytes.data(),
                               static_cast<int>(bytes.size()), nullptr)) {
    if (const std::optional<PngHeader> png = png_header(bytes)) {
      // stb_image's two limits: its header test (under 1 GB in the file's own channels, in its
      // integer arithmetic), and the RGBA image tinygltf asks for (under 2 GB, at 16 bits for a
      // 16-bit file).
      const double rgba_bytes =
          static_cast<double>(png->width) * png->height * 4 * (png->bits == 16 ? 2 : 1);
      if (png->width > 0 && ((std::uint32_t{1} << 30) / png->width / png->channels < png->height ||
                             rgba_bytes > std::numeric_limits<int>::max())) {
        fail(
            "{} is {} x {} pixels{}: more than the image decoder takes (under 1 GB in the file's "
            "channels and 2 GB as RGBA); scale it down (16384 x 16384 at 8 bits fits)",
            what, png->width, png->height, png->bits == 16 ? " at 16 bits" : "");
      }
    }
    fail("{} could not be decoded (unknown or broken image format)", what);
  }
  return make_texture(std::move(source), image.width, image.height, image.component, image.bits,
                      image.image, what);
}

// ---------------------------------------------------------------------------------------------
// glTF 2.0 through tinygltf.

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
    const Eigen::Matrix3f linear = world.topLeftCorner<3, 3>().cast<float>();
    const Vector3f offset = world.topRightCorner<3, 1>().cast<float>();
    bool normals_ok = false;
    const Eigen::Matrix3f to_normal =
        normal_matrix(world.topLeftCorner<3, 3>(), &normals_ok).cast<float>();
    const bool flip = world.topLeftCorner<3, 3>().determinant() < 0;

    for (std::size_t pi = 0; pi < mesh.primitives.size(); ++pi) {
      const tinygltf::Primitive& prim = mesh.primitives[pi];
      const int mode = prim.mode < 0 ? TINYGLTF_MODE_TRIANGLES : prim.mode;
      if (mode != TINYGLTF_MODE_TRIANGLES && mode != TINYGLTF_MODE_TRIANGLE_STRIP &&
          mode != TINYGLTF_MODE_TRIANGLE_FAN) {
        ++skipped_primitives_;
        continue;
      }
      const auto pos_it = prim.attributes.find("POSITION");
      if (pos_it == prim.attributes.end()) {
        fail("mesh {} primitive {} has no POSITION attribute", mesh_index, pi);
      }
      const AccessorView positions =
          view_accessor(model_, pos_it->second, "POSITION", TINYGLTF_TYPE_VEC3,
                        {TINYGLTF_COMPONENT_TYPE_FLOAT, TINYGLTF_COMPONENT_TYPE_BYTE,
                         TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE, TINYGLTF_COMPONENT_TYPE_SHORT,
                         TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT});
      const std::size_t vertex_count = positions.count;
      if (vertex_count > kMaxVertices) fail("mesh {} has too many vertices", mesh_index);

      AccessorView normals, uvs;
      bool has_normals = false, has_uvs = false;
      if (auto it = prim.attributes.find("NORMAL"); it != prim.attributes.end()) {
        normals = view_accessor(model_, it->second, "NORMAL", TINYGLTF_TYPE_VEC3,
                                {TINYGLTF_COMPONENT_TYPE_FLOAT, TINYGLTF_COMPONENT_TYPE_BYTE,
                                 TINYGLTF_COMPONENT_TYPE_SHORT});
        if (normals.count != vertex_count) {
          fail("accessor {} (NORMAL) has {} elements but POSITION has {}", it->second,
               normals.count, vertex_count);
        }
        has_normals = true;
      }
      if (auto it = prim.attributes.find("TEXCOORD_0"); it != prim.attributes.end()) {
        uvs = view_accessor(model_, it->second, "TEXCOORD_0", TINYGLTF_TYPE_VEC2,
                            {TINYGLTF_COMPONENT_TYPE_FLOAT, TINYGLTF_COMPONENT_TYPE_BYTE,
                             TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE, TINYGLTF_COMPONENT_TYPE_SHORT,
                             TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT});
        if (uvs.count != vertex_count) {
          fail("accessor {} (TEXCOORD_0) has {} elements but POSITION has {}", it->second,
               uvs.count, vertex_count);
        }
        has_uvs = true;
      }

      // Corner indices of the triangles, checked against the vertex count.
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
      std::vector<std::uint32_t> corners;
      if (mode == TINYGLTF_MODE_TRIANGLES) {
        if (indices.size() % 3 != 0) {
          fail("mesh {} primitive {} has {} indices, not a multiple of 3", mesh_index, pi,
               indices.size());
        }
        corners = std::move(indices);
      } else if (indices.size() >= 3) {
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
      }
      if (corners.empty()) continue;

      int material = prim.material;
      if (material < 0) {
        material = default_material();
      } else if (static_cast<std::size_t>(material) >= model_.materials.size()) {
        fail("mesh {} primitive {} uses material {}, which does not exist", mesh_index, pi,
             material);
      }

      // Copy only the vertices the triangles use, in order of first use.
      std::vector<std::uint32_t> remap(vertex_count, kNone);
      std::vector<std::uint32_t> used;
      used.reserve(std::min(vertex_count, corners.size()));
      for (std::uint32_t& c : corners) {
        if (remap[c] == kNone) {
          remap[c] = static_cast<std::uint32_t>(used.size());
          used.push_back(c);
        }
        c = remap[c];
      }
      const std::uint32_t base = builder_.add_vertices(used.size());
      bool primitive_normals_ok = has_normals && normals_ok;
      for (std::size_t k = 0; k < used.size(); ++k) {
        const std::uint32_t src = used[k];
        const std::uint32_t dst = base + static_cast<std::uint32_t>(k);
        const Vector3f p = read_vec<3>(positions, src);
        if (!p.allFinite()) {
          fail("mesh {} '{}' vertex {} has a position that is not finite ({}, {}, {})", mesh_index,
               mesh.name, src, p.x(), p.y(), p.z());
        }
        builder_.position(dst) = linear * p + offset;
        if (primitive_normals_ok) {
          const Vector3f n = to_normal * read_vec<3>(normals, src);
          const float len = n.norm();
          if (!std::isfinite(len) || len < 1e-6f) {
            primitive_normals_ok = false;  // a broken normal: compute this primitive's normals
          } else {
            builder_.normal(dst) = n / len;
          }
        }
        if (has_uvs) {
          const Eigen::Vector2f uv = read_vec<2>(uvs, src);
          if (uv.allFinite()) builder_.uv(dst) = uv;
        }
      }
      if (!primitive_normals_ok) {
        for (std::size_t k = 0; k < used.size(); ++k) builder_.normal(base + k) = Vector3f::Zero();
        builder_.set_needs_normal(base, used.size());
      }
      if (has_uvs) builder_.set_has_uvs();
      builder_.reserve_triangles(corners.size() / 3);
      for (std::size_t i = 0; i < corners.size(); i += 3) {
        builder_.add_triangle(base + corners[i], base + corners[i + 1], base + corners[i + 2],
                              material, flip);
      }
    }
  }

  const std::string& path_;
  const tinygltf::Model& model_;
  LoadedModel* out_;
  Builder builder_;
  std::map<int, int> image_to_texture_;
  int default_material_ = -1;
  int skipped_primitives_ = 0;
};

// tinygltf accepts many wrongly typed members by ignoring them (a "scene": "hello" silently
// becomes scene 0, a texture index of the wrong type drops the texture). This checks the types of
// the members RigC reads, and the required extensions, before tinygltf runs.
class GltfSchemaCheck {
 public:
  using json = nlohmann::json;

  void run(const json& root) {
    object(root, "the top level");
    if (!root.contains("asset")) fail("has no 'asset' (not a glTF 2.0 file)");
    const json& asset = object(root["asset"], "asset");
    const json* version = member(asset, "version");
    if (!version || !version->is_string()) {
      fail("is not a glTF 2.0 file (asset.version is {})", version ? version->dump() : "missing");
    }
    if (version->get<std::string>().rfind("2.", 0) != 0) {
      fail("is glTF version {}; only glTF 2.x is supported", version->get<std::string>());
    }
    if (const json* required = member(root, "extensionsRequired")) {
      for (const json& ext : array(*required, "extensionsRequired")) {
        if (!ext.is_string()) fail("extensionsRequired must hold strings");
        const std::string name = ext.get<std::string>();
        if (name != "KHR_materials_pbrSpecularGlossiness" && name != "KHR_mesh_quantization" &&
            name != "KHR_materials_unlit") {
          fail("requires the glTF extension {}, which is not supported", name);
        }
      }
    }
    index(root, "scene", "");
    each(root, "scenes", [&](const json& o, const std::string& at) {
      string(o, "name", at);
      indices(o, "nodes", at);
    });
    each(root, "nodes", [&](const json& o, const std::string& at) {
      string(o, "name", at);
      index(o, "mesh", at);
      indices(o, "children", at);
      numbers(o, "matrix", 16, at);
      numbers(o, "translation", 3, at);
      numbers(o, "rotation", 4, at);
      numbers(o, "scale", 3, at);
    });
    each(root, "meshes", [&](const json& o, const std::string& at) {
      string(o, "name", at);
      const json* prims = member(o, "primitives");
      if (!prims) fail("{}.primitives is missing", at);
      const json& list = array(*prims, at + ".primitives");
      for (std::size_t i = 0; i < list.size(); ++i) {
        const std::string pat = fmt::format("{}.primitives[{}]", at, i);
        const json& prim = object(list[i], pat);
        const json* attrs = member(prim, "attributes");
        if (!attrs) fail("{}.attributes is missing", pat);
        for (const auto& [key, value] : object(*attrs, pat + ".attributes").items()) {
          if (!value.is_number_integer() || value.get<std::int64_t>() < 0) {
            fail("{}.attributes.{} must be an index (it is {})", pat, key, value.type_name());
          }
        }
        index(prim, "indices", pat);
        index(prim, "material", pat);
        index(prim, "mode", pat);
      }
    });
    each(root, "accessors", [&](const json& o, const std::string& at) {
      index(o, "bufferView", at);
      index(o, "byteOffset", at);
      index(o, "componentType", at);
      index(o, "count", at);
      string(o, "type", at);
    });
    each(root, "bufferViews", [&](const json& o, const std::string& at) {
      index(o, "buffer", at);
      index(o, "byteOffset", at);
      index(o, "byteLength", at);
      index(o, "byteStride", at);
    });
    each(root, "buffers", [&](const json& o, const std::string& at) {
      index(o, "byteLength", at);
      string(o, "uri", at);
    });
    each(root, "materials", [&](const json& o, const std::string& at) {
      string(o, "name", at);
      if (const json* pbr = member(o, "pbrMetallicRoughness")) {
        const std::string pat = at + ".pbrMetallicRoughness";
        object(*pbr, pat);
        numbers(*pbr, "baseColorFactor", 4, pat);
        number(*pbr, "metallicFactor", pat);
        number(*pbr, "roughnessFactor", pat);
        texture_info(*pbr, "baseColorTexture", pat);
        texture_info(*pbr, "metallicRoughnessTexture", pat);
      }
      texture_info(o, "normalTexture", at);
      texture_info(o, "occlusionTexture", at);
      texture_info(o, "emissiveTexture", at);
      if (const json* t = member(o, "normalTexture")) number(*t, "scale", at + ".normalTexture");
      if (const json* t = member(o, "occlusionTexture")) {
        number(*t, "strength", at + ".occlusionTexture");
      }
    });
    each(root, "textures", [&](const json& o, const std::string& at) {
      index(o, "source", at);
      index(o, "sampler", at);
    });
    each(root, "images", [&](const json& o, const std::string& at) {
      string(o, "name", at);
      string(o, "uri", at);
      string(o, "mimeType", at);
      index(o, "bufferView", at);
    });
  }

 private:
  static std::string join(const std::string& at, const char* key) {
    return at.empty() ? std::string(key) : at + "." + key;
  }
  static const json& object(const json& j, const std::string& at) {
    if (!j.is_object()) fail("{} must be an object (it is {})", at, j.type_name());
    check_extensions(j, at);
    return j;
  }
  static const json& array(const json& j, const std::string& at) {
    if (!j.is_array()) fail("{} must be an array (it is {})", at, j.type_name());
    return j;
  }
  // Every "extensions" member is an object of objects.
  static void check_extensions(const json& o, const std::string& at) {
    const auto it = o.find("extensions");
    if (it == o.end()) return;
    if (!it->is_object()) fail("{}.extensions must be an object", at);
    for (const auto& [key, value] : it->items()) {
      if (!value.is_object()) fail("{}.extensions.{} must be an object", at, key);
    }
  }
  static const json* member(const json& o, const char* key) {
    const auto it = o.find(key);
    return it == o.end() ? nullptr : &*it;
  }
  static void index(const json& o, const char* key, const std::string& at) {
    if (const json* v = member(o, key)) {
      if (!v->is_number_integer() || v->get<std::int64_t>() < 0) {
        fail("{} must be a non-negative integer (it is {} {})", join(at, key), v->type_name(),
             v->dump());
      }
    }
  }
  static void indices(const json& o, const char* key, const std::string& at) {
    if (const json* v = member(o, key)) {
      for (const json& e : array(*v, join(at, key))) {
        if (!e.is_number_integer() || e.get<std::int64_t>() < 0) {
          fail("{} must hold non-negative integers", join(at, key));
        }
      }
    }
  }
  static void number(const json& o, const char* key, const std::string& at) {
    if (const json* v = member(o, key); v && !v->is_number()) {
      fail("{} must be a number (it is {})", join(at, key), v->type_name());
    }
  }
  static void numbers(const json& o, const char* key, std::size_t n, const std::string& at) {
    if (const json* v = member(o, key)) {
      const json& a = array(*v, join(at, key));
      if (a.size() != n) fail("{} must have {} numbers (it has {})", join(at, key), n, a.size());
      for (const json& e : a) {
        if (!e.is_number()) fail("{} must hold numbers", join(at, key));
      }
    }
  }
  static void string(const json& o, const char* key, const std::string& at) {
    if (const json* v = member(o, key); v && !v->is_string()) {
      fail("{} must be a string (it is {})", join(at, key), v->type_name());
    }
  }
  static void texture_info(const json& o, const char* key, const std::string& at) {
    if (const json* v = member(o, key)) {
      const std::string pat = join(at, key);
      object(*v, pat);
      if (!v->contains("index")) fail("{}.index is missing", pat);
      index(*v, "index", pat);
      index(*v, "texCoord", pat);
    }
  }
  template <typename F>
  void each(const json& root, const char* key, F&& f) {
    if (const json* v = member(root, key)) {
      const json& a = array(*v, key);
      for (std::size_t i = 0; i < a.size(); ++i) {
        const std::string at = fmt::format("{}[{}]", key, i);
        f(object(a[i], at), at);
      }
    }
  }
};

// The JSON text of a .gltf file, or of a .glb's JSON chunk; empty if it cannot be found (tinygltf
// then reports the problem).
std::string gltf_json_text(const std::string& path, bool binary) {
  std::ifstream in(path, std::ios::binary);
  if (!in) return {};
  if (!binary) return std::string(std::istreambuf_iterator<char>(in), {});
  unsigned char header[20];
  if (!in.read(reinterpret_cast<char*>(header), 20)) return {};
  auto u32 = [&](int at) {
    return static_cast<std::uint32_t>(header[at]) |
           static_cast<std::uint32_t>(header[at + 1]) << 8 |
           static_cast<std::uint32_t>(header[at + 2]) << 16 |
           static_cast<std::uint32_t>(header[at + 3]) << 24;
  };
  if (std::memcmp(header, "glTF", 4) != 0 || u32(16) != 0x4E4F534AU) return {};
  const std::uint32_t length = u32(12);
  std::error_code ec;
  const auto file_size = fs::file_size(path, ec);
  if (ec || length > file_size) return {};
  std::string text(length, '\0');
  if (!in.read(text.data(), length)) return {};
  return text;
}

LoadedModel load_gltf(const std::string& path, bool binary) {
  {
    const nlohmann::json root =
        nlohmann::json::parse(gltf_json_text(path, binary), nullptr, /*allow_exceptions=*/false);
    if (!root.is_discarded()) GltfSchemaCheck().run(root);
  }
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

// ---------------------------------------------------------------------------------------------
// PLY: read natively (Assimp's PLY reader takes about 0.35 s for a million triangles; this one
// takes a few tens of milliseconds). ASCII and binary, any element order, lists anywhere.

enum class PlyType { kInt8, kUint8, kInt16, kUint16, kInt32, kUint32, kFloat32, kFloat64 };

std::optional<PlyType> ply_type(const std::string& name) {
  if (name == "char" || name == "int8") return PlyType::kInt8;
  if (name == "uchar" || name == "uint8") return PlyType::kUint8;
  if (name == "short" || name == "int16") return PlyType::kInt16;
  if (name == "ushort" || name == "uint16") return PlyType::kUint16;
  if (name == "int" || name == "int32") return PlyType::kInt32;
  if (name == "uint" || name == "uint32") return PlyType::kUint32;
  if (name == "float" || name == "float32") return PlyType::kFloat32;
  if (name == "double" || name == "float64") return PlyType::kFloat64;
  return std::nullopt;
}

std::size_t ply_size(PlyType t) {
  switch (t) {
    case PlyType::kInt8:
    case PlyType::kUint8:
      return 1;
    case PlyType::kInt16:
    case PlyType::kUint16:
      return 2;
    case PlyType::kInt32:
    case PlyType::kUint32:
    case PlyType::kFloat32:
      return 4;
    case PlyType::kFloat64:
      return 8;
  }
  return 1;
}

struct PlyProperty {
  std::string name;
  PlyType type = PlyType::kFloat32;
  bool is_list = false;
  PlyType count_type = PlyType::kUint8;
};

struct PlyElement {
  std::string name;
  std::size_t count = 0;
  std::vector<PlyProperty> properties;
};

enum class PlyFormat { kAscii, kBinaryLittle, kBinaryBig };

// Reads the values of one element instance after another, in ASCII or binary.
class PlyCursor {
 public:
  PlyCursor(const char* begin, const char* end, PlyFormat format)
      : p_(begin), end_(end), format_(format) {}

  double read(PlyType type) {
    if (format_ == PlyFormat::kAscii) return read_ascii();
    const std::size_t size = ply_size(type);
    if (static_cast<std::size_t>(end_ - p_) < size) fail("ends early (truncated data)");
    unsigned char b[8];
    std::memcpy(b, p_, size);
    p_ += size;
    if ((format_ == PlyFormat::kBinaryBig) == (std::endian::native == std::endian::little)) {
      std::reverse(b, b + size);
    }
    switch (type) {
      case PlyType::kInt8:
        return static_cast<std::int8_t>(b[0]);
      case PlyType::kUint8:
        return b[0];
      case PlyType::kInt16:
        return load<std::int16_t>(b);
      case PlyType::kUint16:
        return load<std::uint16_t>(b);
      case PlyType::kInt32:
        return load<std::int32_t>(b);
      case PlyType::kUint32:
        return load<std::uint32_t>(b);
      case PlyType::kFloat32:
        return load<float>(b);
      case PlyType::kFloat64:
        return load<double>(b);
    }
    return 0;
  }

  std::size_t remaining() const { return static_cast<std::size_t>(end_ - p_); }

 private:
  template <typename T>
  static double load(const unsigned char* b) {
    T v;
    std::memcpy(&v, b, sizeof(T));
    return static_cast<double>(v);
  }

  double read_ascii() {
    while (p_ < end_ && std::isspace(static_cast<unsigned char>(*p_))) ++p_;
    if (p_ == end_) fail("ends early (truncated data)");
    const char* start = p_;
    while (p_ < end_ && !std::isspace(static_cast<unsigned char>(*p_))) ++p_;
    double v = 0;
    const char* first = start;
    if (*first == '+') ++first;
    const auto [ptr, ec] = std::from_chars(first, p_, v);
    if (ec != std::errc() || ptr != p_) {
      // from_chars does not take "inf"/"nan" spelled every way; let strtod decide.
      const std::string token(start, p_);
      char* parse_end = nullptr;
      v = std::strtod(token.c_str(), &parse_end);
      if (parse_end != token.c_str() + token.size()) fail("has a bad number '{}'", token);
    }
    return v;
  }

  const char* p_;
  const char* end_;
  PlyFormat format_;
};

LoadedModel load_ply(const std::string& path) {
  const std::vector<unsigned char> bytes = read_file_bytes(path);
  const char* data = reinterpret_cast<const char*>(bytes.data());
  const char* end = data + bytes.size();

  // Header.
  const char* p = data;
  auto next_line = [&]() -> std::optional<std::string> {
    if (p >= end) return std::nullopt;
    const char* nl = static_cast<const char*>(std::memchr(p, '\n', end - p));
    const char* line_end = nl ? nl : end;
    std::string line(p, line_end);
    p = nl ? nl + 1 : end;
    if (!line.empty() && line.back() == '\r') line.pop_back();
    return line;
  };
  auto words = [](const std::string& line) {
    std::vector<std::string> out;
    std::size_t i = 0;
    while (i < line.size()) {
      while (i < line.size() && std::isspace(static_cast<unsigned char>(line[i]))) ++i;
      std::size_t j = i;
      while (j < line.size() && !std::isspace(static_cast<unsigned char>(line[j]))) ++j;
      if (j > i) out.push_back(line.substr(i, j - i));
      i = j;
    }
    return out;
  };
  if (auto first = next_line(); !first || words(*first) != std::vector<std::string>{"ply"}) {
    fail("is not a PLY file (no 'ply' magic)");
  }
  std::optional<PlyFormat> format;
  std::vector<PlyElement> elements;
  std::string texture_file;
  bool ended = false;
  for (int line_no = 2; !ended; ++line_no) {
    const auto line = next_line();
    if (!line) fail("has no end_header");
    const std::vector<std::string> w = words(*line);
    if (w.empty()) continue;
    if (w[0] == "end_header") {
      ended = true;
    } else if (w[0] == "format") {
      if (w.size() < 2) fail("header line {}: malformed format", line_no);
      if (w[1] == "ascii") {
        format = PlyFormat::kAscii;
      } else if (w[1] == "binary_little_endian") {
        format = PlyFormat::kBinaryLittle;
      } else if (w[1] == "binary_big_endian") {
        format = PlyFormat::kBinaryBig;
      } else {
        fail("header line {}: unknown format '{}'", line_no, w[1]);
      }
    } else if (w[0] == "element") {
      if (w.size() != 3) fail("header line {}: malformed element", line_no);
      PlyElement e;
      e.name = w[1];
      const auto [ptr, ec] = std::from_chars(w[2].data(), w[2].data() + w[2].size(), e.count);
      if (ec != std::errc() || ptr != w[2].data() + w[2].size()) {
        fail("header line {}: bad element count '{}'", line_no, w[2]);
      }
      elements.push_back(std::move(e));
    } else if (w[0] == "property") {
      if (elements.empty()) fail("header line {}: property before any element", line_no);
      PlyProperty prop;
      if (w.size() == 5 && w[1] == "list") {
        const auto count_type = ply_type(w[2]);
        const auto item_type = ply_type(w[3]);
        if (!count_type || !item_type) fail("header line {}: unknown property type", line_no);
        if (*count_type == PlyType::kFloat32 || *count_type == PlyType::kFloat64) {
          fail("header line {}: list count type must be an integer", line_no);
        }
        prop.is_list = true;
        prop.count_type = *count_type;
        prop.type = *item_type;
        prop.name = w[4];
      } else if (w.size() == 3) {
        const auto type = ply_type(w[1]);
        if (!type) fail("header line {}: unknown property type '{}'", line_no, w[1]);
        prop.type = *type;
        prop.name = w[2];
      } else {
        fail("header line {}: malformed property", line_no);
      }
      elements.back().properties.push_back(std::move(prop));
    } else if (w[0] == "comment" && w.size() >= 3 && lower(w[1]) == "texturefile") {
      texture_file = line->substr(line->find(w[1]) + w[1].size());
      texture_file.erase(0, texture_file.find_first_not_of(" \t"));
    }
    // Other lines (comment, obj_info, and stray text some exporters write) are ignored.
  }
  if (!format) fail("has no format line");

  // Guard against absurd counts: every element instance takes at least one byte (binary) or
  // two characters (ASCII) per property.
  for (const PlyElement& e : elements) {
    std::size_t per = 0;
    for (const PlyProperty& prop : e.properties) {
      per += *format == PlyFormat::kAscii
                 ? 2
                 : (prop.is_list ? ply_size(prop.count_type) : ply_size(prop.type));
    }
    if (per > 0 && e.count > (static_cast<std::size_t>(end - p) + 1) / per) {
      fail("is truncated: element '{}' claims {} entries, more than the file holds", e.name,
           e.count);
    }
  }

  LoadedModel out;
  ir::Material material;
  material.name = "default";
  out.materials.push_back(std::move(material));
  Builder builder(&out);

  PlyCursor cursor(p, end, *format);
  std::size_t vertex_count = 0;
  bool seen_vertices = false;
  bool has_normals = false, has_uvs = false, normals_ok = true;
  std::vector<std::uint32_t> polygon;
  for (const PlyElement& e : elements) {
    if (e.name == "vertex") {
      if (seen_vertices) fail("has two vertex elements");
      seen_vertices = true;
      // Property slots: x y z nx ny nz u v.
      std::vector<int> slot(e.properties.size(), -1);
      static const std::vector<std::vector<std::string>> kNames = {
          {"x"},
          {"y"},
          {"z"},
          {"nx"},
          {"ny"},
          {"nz"},
          {"s", "u", "texture_u", "texture_s"},
          {"t", "v", "texture_v", "texture_t"}};
      std::array<bool, 8> found{};
      for (std::size_t k = 0; k < e.properties.size(); ++k) {
        if (e.properties[k].is_list) continue;
        for (int s = 0; s < 8; ++s) {
          const auto& names = kNames[s];
          if (!found[s] &&
              std::find(names.begin(), names.end(), e.properties[k].name) != names.end()) {
            slot[k] = s;
            found[s] = true;
          }
        }
      }
      if (!found[0] || !found[1] || !found[2]) fail("vertex element has no x, y, z properties");
      has_normals = found[3] && found[4] && found[5];
      has_uvs = found[6] && found[7];
      vertex_count = e.count;
      if (vertex_count > kMaxVertices) fail("has too many vertices ({})", vertex_count);
      builder.add_vertices(vertex_count);
      double values[8];
      for (std::size_t i = 0; i < e.count; ++i) {
        std::fill(values, values + 8, 0.0);
        for (std::size_t k = 0; k < e.properties.size(); ++k) {
          const PlyProperty& prop = e.properties[k];
          if (prop.is_list) {
            const double n = cursor.read(prop.count_type);
            if (n < 0 || n > static_cast<double>(cursor.remaining())) fail("has a bad list length");
            for (std::size_t j = 0; j < static_cast<std::size_t>(n); ++j) cursor.read(prop.type);
            continue;
          }
          const double v = cursor.read(prop.type);
          if (slot[k] >= 0) values[slot[k]] = v;
        }
        const auto index = static_cast<std::uint32_t>(i);
        const Vector3f pos(static_cast<float>(values[0]), static_cast<float>(values[1]),
                           static_cast<float>(values[2]));
        if (!pos.allFinite()) {
          fail("vertex {} has a position that is not finite ({}, {}, {})", i, values[0], values[1],
               values[2]);
        }
        builder.position(index) = pos;
        if (has_normals) {
          const Vector3f n(static_cast<float>(values[3]), static_cast<float>(values[4]),
                           static_cast<float>(values[5]));
          const float len = n.norm();
          if (!std::isfinite(len) || len < 1e-6f) {
            normals_ok = false;
          } else {
            builder.normal(index) = n / len;
          }
        }
        if (has_uvs) {
          // PLY's t = 0 is the image bottom; RigC's v = 0 is the image top.
          const Vector2f uv(static_cast<float>(values[6]), 1.0f - static_cast<float>(values[7]));
          if (uv.allFinite()) builder.uv(index) = uv;
        }
      }
    } else if (e.name == "face") {
      if (!seen_vertices) fail("face element comes before the vertex element");
      int list = -1;
      for (std::size_t k = 0; k < e.properties.size(); ++k) {
        const PlyProperty& prop = e.properties[k];
        if (prop.is_list && (prop.name == "vertex_indices" || prop.name == "vertex_index")) {
          list = static_cast<int>(k);
          break;
        }
      }
      if (list < 0) fail("face element has no vertex_indices list");
      builder.reserve_triangles(e.count);
      for (std::size_t f = 0; f < e.count; ++f) {
        for (std::size_t k = 0; k < e.properties.size(); ++k) {
          const PlyProperty& prop = e.properties[k];
          if (!prop.is_list) {
            cursor.read(prop.type);
            continue;
          }
          const double n = cursor.read(prop.count_type);
          if (n < 0 || n > static_cast<double>(cursor.remaining())) {
            fail("face {} has a bad vertex count {}", f, n);
          }
          const auto count = static_cast<std::size_t>(n);
          if (static_cast<int>(k) != list) {
            for (std::size_t j = 0; j < count; ++j) cursor.read(prop.type);
            continue;
          }
          polygon.clear();
          for (std::size_t j = 0; j < count; ++j) {
            const double v = cursor.read(prop.type);
            if (!(v >= 0 && v < static_cast<double>(vertex_count))) {
              fail("face {} index {} is out of range ({} vertices)", f, v, vertex_count);
            }
            polygon.push_back(static_cast<std::uint32_t>(v));
          }
          // Polygons are split into a fan.
          for (std::size_t j = 1; j + 1 < polygon.size(); ++j) {
            builder.add_triangle(polygon[0], polygon[j], polygon[j + 1], 0, false);
          }
        }
      }
    } else {
      for (std::size_t i = 0; i < e.count; ++i) {
        for (const PlyProperty& prop : e.properties) {
          if (prop.is_list) {
            const double n = cursor.read(prop.count_type);
            if (n < 0 || n > static_cast<double>(cursor.remaining())) fail("has a bad list length");
            for (std::size_t j = 0; j < static_cast<std::size_t>(n); ++j) cursor.read(prop.type);
          } else {
            cursor.read(prop.type);
          }
        }
      }
    }
  }
  if (!has_normals || !normals_ok) builder.set_needs_normal(0, vertex_count);
  if (has_uvs) builder.set_has_uvs();
  if (!texture_file.empty()) {
    const fs::path file = (fs::path(path).parent_path() / texture_file).lexically_normal();
    std::error_code ec;
    if (!fs::is_regular_file(file, ec)) fail("texture '{}' not found", file.string());
    out.textures.push_back(decode_image(file.string(), read_file_bytes(file),
                                        fmt::format("texture '{}'", file.string())));
    out.materials[0].base_color_texture = 0;
    out.materials[0].base_color = Vector3d(1, 1, 1);
  }
  builder.finish();
  return out;
}

// ---------------------------------------------------------------------------------------------
// OBJ and STL through Assimp.

Mat4 to_mat4(const aiMatrix4x4& m) {
  Mat4 out;
  for (int r = 0; r < 4; ++r) {
    for (int c = 0; c < 4; ++c) out(r, c) = m[r][c];
  }
  return out;
}

class AssimpLoader {
 public:
  // STL's facet normals are ignored: the welded mesh gets smooth normals.
  AssimpLoader(const std::string& path, const aiScene& scene, bool use_file_normals,
               LoadedModel* out)
      : path_(path), scene_(scene), use_file_normals_(use_file_normals), out_(out), builder_(out) {}

  void run() {
    for (unsigned i = 0; i < scene_.mNumMaterials; ++i) convert_material(i);
    if (out_->materials.empty()) {
      ir::Material mat;
      mat.name = "default";
      out_->materials.push_back(std::move(mat));
    }
    if (!scene_.mRootNode) fail("has no root node");
    std::vector<std::pair<const aiNode*, Mat4>> stack = {{scene_.mRootNode, Mat4::Identity()}};
    while (!stack.empty()) {
      auto [node, parent] = std::move(stack.back());
      stack.pop_back();
      const Mat4 world = parent * to_mat4(node->mTransformation);
      if (!world.allFinite()) {
        fail("node '{}' has a transform that is not finite", node->mName.C_Str());
      }
      for (unsigned i = 0; i < node->mNumMeshes; ++i) {
        const unsigned mesh = node->mMeshes[i];
        if (mesh >= scene_.mNumMeshes) {
          fail("node '{}' uses mesh {}, which does not exist", node->mName.C_Str(), mesh);
        }
        add_mesh(*scene_.mMeshes[mesh], world);
      }
      for (unsigned i = node->mNumChildren; i-- > 0;) stack.emplace_back(node->mChildren[i], world);
    }
    builder_.finish();
  }

 private:
  void convert_material(unsigned index) {
    const aiMaterial& m = *scene_.mMaterials[index];
    ir::Material mat;
    aiString name;
    mat.name = m.Get(AI_MATKEY_NAME, name) == AI_SUCCESS && name.length > 0
                   ? std::string(name.C_Str())
                   : fmt::format("material{}", index);
    aiColor4D color;
    if (m.Get(AI_MATKEY_BASE_COLOR, color) == AI_SUCCESS ||
        m.Get(AI_MATKEY_COLOR_DIFFUSE, color) == AI_SUCCESS) {
      const Vector3d c(color.r, color.g, color.b);
      if (c.allFinite()) mat.base_color = c.cwiseMax(0.0).cwiseMin(1.0);
    }
    ai_real value;
    if (m.Get(AI_MATKEY_ROUGHNESS_FACTOR, value) == AI_SUCCESS && std::isfinite(value)) {
      mat.roughness = std::clamp<double>(value, 0.0, 1.0);
    }
    if (m.Get(AI_MATKEY_METALLIC_FACTOR, value) == AI_SUCCESS && std::isfinite(value)) {
      mat.metallic = std::clamp<double>(value, 0.0, 1.0);
    }
    aiString texture;
    if (m.GetTexture(aiTextureType_BASE_COLOR, 0, &texture) == AI_SUCCESS ||
        m.GetTexture(aiTextureType_DIFFUSE, 0, &texture) == AI_SUCCESS) {
      if (texture.length > 0) mat.base_color_texture = load_texture(texture.C_Str(), mat.name);
    }
    out_->materials.push_back(std::move(mat));
  }

  int load_texture(const std::string& reference, const std::string& material) {
    if (auto it = textures_.find(reference); it != textures_.end()) return it->second;
    ir::Texture tex;
    if (const aiTexture* embedded = scene_.GetEmbeddedTexture(reference.c_str())) {
      const std::string what = fmt::format("embedded texture '{}'", reference);
      const std::string source = fmt::format("{}#{}", path_, reference);
      if (embedded->mHeight == 0) {
        const auto* bytes = reinterpret_cast<const unsigned char*>(embedded->pcData);
        tex =
            decode_image(source, std::vector<unsigned char>(bytes, bytes + embedded->mWidth), what);
      } else {
        std::vector<unsigned char> rgba(static_cast<std::size_t>(embedded->mWidth) *
                                        embedded->mHeight * 4);
        for (std::size_t i = 0; i < rgba.size() / 4; ++i) {
          const aiTexel& t = embedded->pcData[i];
          rgba[4 * i + 0] = t.r;
          rgba[4 * i + 1] = t.g;
          rgba[4 * i + 2] = t.b;
          rgba[4 * i + 3] = t.a;
        }
        tex = make_texture(source, static_cast<int>(embedded->mWidth),
                           static_cast<int>(embedded->mHeight), 4, 8, rgba, what);
      }
    } else {
      // Paths written on Windows use backslashes; resolve relative to the model's folder.
      std::string clean = reference;
      std::replace(clean.begin(), clean.end(), '\\', '/');
      const fs::path dir = fs::path(path_).parent_path();
      fs::path file = fs::path(clean).is_absolute() ? fs::path(clean) : dir / clean;
      std::error_code ec;
      if (!fs::is_regular_file(file, ec)) {
        const fs::path beside = dir / fs::path(clean).filename();
        if (!fs::is_regular_file(beside, ec)) {
          fail("texture '{}' of material '{}' not found (looked for {})", reference, material,
               file.lexically_normal().string());
        }
        file = beside;
      }
      file = file.lexically_normal();
      tex = decode_image(file.string(), read_file_bytes(file),
                         fmt::format("texture '{}'", file.string()));
    }
    out_->textures.push_back(std::move(tex));
    const int index = static_cast<int>(out_->textures.size() - 1);
    textures_[reference] = index;
    return index;
  }

  void add_mesh(const aiMesh& mesh, const Mat4& world) {
    if (!(mesh.mPrimitiveTypes & aiPrimitiveType_TRIANGLE) || mesh.mNumFaces == 0 ||
        !mesh.mVertices) {
      return;
    }
    const Eigen::Matrix3f linear = world.topLeftCorner<3, 3>().cast<float>();
    const Vector3f offset = world.topRightCorner<3, 1>().cast<float>();
    bool normals_ok = false;
    const Eigen::Matrix3f to_normal =
        normal_matrix(world.topLeftCorner<3, 3>(), &normals_ok).cast<float>();
    const bool flip = world.topLeftCorner<3, 3>().determinant() < 0;
    const int material =
        mesh.mMaterialIndex < out_->materials.size() ? static_cast<int>(mesh.mMaterialIndex) : 0;

    const std::uint32_t n = mesh.mNumVertices;
    for (std::uint32_t i = 0; i < n; ++i) {
      const aiVector3D& v = mesh.mVertices[i];
      if (!std::isfinite(v.x) || !std::isfinite(v.y) || !std::isfinite(v.z)) {
        fail("mesh '{}' vertex {} has a position that is not finite ({}, {}, {})",
             mesh.mName.C_Str(), i, v.x, v.y, v.z);
      }
    }
    const aiVector3D* file_normals = use_file_normals_ ? mesh.mNormals : nullptr;
    const aiVector3D* uvs = mesh.mTextureCoords[0];
    // OBJ and STL give every triangle corner its own vertex: weld the identical ones.
    std::vector<std::uint32_t> remap, keep;
    weld_identical(mesh, file_normals, uvs, &remap, &keep);

    const std::uint32_t base = builder_.add_vertices(keep.size());
    bool has_normals = file_normals != nullptr && normals_ok;
    for (std::uint32_t k = 0; k < keep.size(); ++k) {
      const std::uint32_t i = keep[k];
      const aiVector3D& v = mesh.mVertices[i];
      builder_.position(base + k) = linear * Vector3f(v.x, v.y, v.z) + offset;
      if (has_normals) {
        const aiVector3D& an = file_normals[i];
        const Vector3f nn = to_normal * Vector3f(an.x, an.y, an.z);
        const float len = nn.norm();
        if (!std::isfinite(len) || len < 1e-6f) {
          has_normals = false;
        } else {
          builder_.normal(base + k) = nn / len;
        }
      }
      if (uvs) {
        // Assimp's v grows upwards from the image bottom; RigC's v = 0 is the image top.
        const Vector2f uv(uvs[i].x, 1.0f - uvs[i].y);
        if (uv.allFinite()) builder_.uv(base + k) = uv;
      }
    }
    if (!has_normals) {
      for (std::uint32_t k = 0; k < keep.size(); ++k) builder_.normal(base + k) = Vector3f::Zero();
      builder_.set_needs_normal(base, keep.size());
    }
    if (uvs) builder_.set_has_uvs();
    builder_.reserve_triangles(mesh.mNumFaces);
    for (unsigned f = 0; f < mesh.mNumFaces; ++f) {
      const aiFace& face = mesh.mFaces[f];
      if (face.mNumIndices != 3) continue;
      for (unsigned k = 0; k < 3; ++k) {
        if (face.mIndices[k] >= n) {
          fail("mesh '{}' face {} index {} is out of range ({} vertices)", mesh.mName.C_Str(), f,
               face.mIndices[k], n);
        }
      }
      builder_.add_triangle(base + remap[face.mIndices[0]], base + remap[face.mIndices[1]],
                            base + remap[face.mIndices[2]], material, flip);
    }
  }

  // Maps every vertex to the first one with bit-identical position (and normal and uv, when they
  // are used): remap[vertex] indexes `keep`, which lists the vertices kept. Assimp's
  // JoinIdenticalVertices does the same but takes 1.5 s for a million triangles; this hash table
  // takes a few tens of milliseconds.
  static void weld_identical(const aiMesh& mesh, const aiVector3D* normals, const aiVector3D* uvs,
                             std::vector<std::uint32_t>* remap, std::vector<std::uint32_t>* keep) {
    const std::uint32_t n = mesh.mNumVertices;
    using Key = std::array<std::uint32_t, 8>;
    auto key = [&](std::uint32_t i) {
      Key k{};
      auto bits = [](float f) { return std::bit_cast<std::uint32_t>(f + 0.0f); };  // -0 -> +0
      k[0] = bits(mesh.mVertices[i].x);
      k[1] = bits(mesh.mVertices[i].y);
      k[2] = bits(mesh.mVertices[i].z);
      if (normals) {
        k[3] = bits(normals[i].x);
        k[4] = bits(normals[i].y);
        k[5] = bits(normals[i].z);
      }
      if (uvs) {
        k[6] = bits(uvs[i].x);
        k[7] = bits(uvs[i].y);
      }
      return k;
    };
    auto hash = [](const Key& k) {
      std::uint64_t h = 0x9e3779b97f4a7c15ULL;
      for (std::uint32_t v : k) h = (h ^ v) * 0xff51afd7ed558ccdULL;
      h ^= h >> 33;  // murmur3's final mix: every bit of the key reaches the low bits
      h *= 0xc4ceb9fe1a85ec53ULL;
      return h ^ (h >> 33);
    };
    const std::size_t size = std::bit_ceil(std::max<std::size_t>(16, 2 * std::size_t{n}));
    std::vector<std::uint32_t> table(size, kNone);  // a kept vertex's index into `keep`
    std::vector<Key> kept_keys;
    remap->assign(n, kNone);
    keep->clear();
    for (std::uint32_t i = 0; i < n; ++i) {
      const Key k = key(i);
      for (std::size_t slot = hash(k) & (size - 1);; slot = (slot + 1) & (size - 1)) {
        if (table[slot] == kNone) {
          table[slot] = static_cast<std::uint32_t>(keep->size());
          (*remap)[i] = table[slot];
          keep->push_back(i);
          kept_keys.push_back(k);
          break;
        }
        if (kept_keys[table[slot]] == k) {
          (*remap)[i] = table[slot];
          break;
        }
      }
    }
  }

  const std::string& path_;
  const aiScene& scene_;
  bool use_file_normals_;
  LoadedModel* out_;
  Builder builder_;
  std::map<std::string, int> textures_;
};

// The material libraries an OBJ names (`mtllib a.mtl b.mtl`) that are not beside it: Assimp
// loads the mesh without them and says nothing, so its colours and textures silently went grey.
std::vector<std::string> missing_material_libraries(const std::string& path) {
  std::vector<std::string> warnings;
  std::ifstream in(path, std::ios::binary);
  std::string line;
  while (std::getline(in, line)) {
    const std::size_t start = line.find_first_not_of(" \t");
    if (start == std::string::npos || line.compare(start, 7, "mtllib ") != 0) continue;
    std::istringstream names(line.substr(start + 7));
    std::string name;
    while (names >> name) {
      std::error_code ec;
      if (!fs::exists(fs::path(path).parent_path() / name, ec)) {
        warnings.push_back(fmt::format(
            "material library '{}' is not beside the mesh: its colours and textures are not used",
            one_line(name)));
      }
    }
  }
  return warnings;
}

LoadedModel load_with_assimp(const std::string& path, const std::string& ext) {
  Assimp::Importer importer;
  // No JoinIdenticalVertices (slow): AssimpLoader welds vertices itself.
  const unsigned flags =
      aiProcess_Triangulate | aiProcess_SortByPType | aiProcess_ValidateDataStructure;
  const aiScene* scene = importer.ReadFile(path, flags);
  if (!scene) {
    const std::string message = one_line(importer.GetErrorString());
    fail("could not be read: {}", message.empty() ? "unknown error" : message);
  }
  if (scene->mFlags & AI_SCENE_FLAGS_INCOMPLETE) fail("is incomplete (no meshes were read)");
  LoadedModel out;
  AssimpLoader(path, *scene, /*use_file_normals=*/ext != ".stl", &out).run();
  if (ext == ".obj") out.warnings = missing_material_libraries(path);
  return out;
}

}  // namespace

std::optional<LoadedModel> load_model(const std::string& path, std::string* error) {
  auto set_error = [&](const std::string& message) {
    if (error) *error = one_line(fmt::format("{}: {}", path, message));
  };
  try {
    std::error_code ec;
    if (!fs::exists(path, ec)) {
      set_error("file not found");
      return std::nullopt;
    }
    if (!fs::is_regular_file(path, ec)) {
      set_error("is not a regular file");
      return std::nullopt;
    }
    const std::string ext = lower(fs::path(path).extension().string());
    if (ext == ".gltf" || ext == ".glb") return load_gltf(path, ext == ".glb");
    if (ext == ".ply") return load_ply(path);
    if (ext == ".obj" || ext == ".stl") return load_with_assimp(path, ext);
    set_error(
        fmt::format("unsupported model format '{}' (use .gltf, .glb, .obj, .ply or .stl)", ext));
  } catch (const LoadError& e) {
    set_error(e.what());
  } catch (const std::bad_alloc&) {
    set_error("out of memory while loading (malformed or too large)");
  } catch (const std::exception& e) {
    set_error(fmt::format("could not be read: {}", e.what()));
  } catch (...) {
    set_error("could not be read: unknown error");
  }
  return std::nullopt;
}

bool write_ply(const std::string& path, const ir::Mesh& mesh, std::string* error) {
  auto failed = [&](const std::string& message) {
    if (error) *error = fmt::format("{}: {}", path, message);
    return false;
  };
  const std::size_t n = mesh.positions.size();
  const bool normals = !mesh.normals.empty();
  const bool uvs = !mesh.uvs.empty();
  if (normals && mesh.normals.size() != n) return failed("normals and positions differ in count");
  if (uvs && mesh.uvs.size() != n) return failed("uvs and positions differ in count");
  if (n > std::numeric_limits<std::uint32_t>::max()) return failed("too many vertices");
  for (const auto& t : mesh.triangles) {
    if (t[0] >= n || t[1] >= n || t[2] >= n) return failed("a triangle index is out of range");
  }

  std::string header = "ply\nformat binary_little_endian 1.0\ncomment written by rigc\n";
  header += fmt::format("element vertex {}\n", n);
  header += "property float x\nproperty float y\nproperty float z\n";
  if (normals) header += "property float nx\nproperty float ny\nproperty float nz\n";
  if (uvs) header += "property float s\nproperty float t\n";
  header += fmt::format("element face {}\n", mesh.triangles.size());
  header += "property list uchar uint vertex_indices\nend_header\n";

  const std::string tmp = temporary_path_beside(path).string();
  std::FILE* file = std::fopen(tmp.c_str(), "wb");
  if (!file) return failed(fmt::format("cannot write: {}", std::strerror(errno)));
  bool ok = std::fwrite(header.data(), 1, header.size(), file) == header.size();

  // Little-endian float and uint32 bytes, written in chunks.
  std::vector<unsigned char> chunk;
  constexpr std::size_t kChunk = 1 << 20;
  chunk.reserve(kChunk + 64);
  auto put32 = [&](std::uint32_t v) {
    if constexpr (std::endian::native == std::endian::big) {
      v = ((v & 0xffU) << 24) | ((v & 0xff00U) << 8) | ((v >> 8) & 0xff00U) | (v >> 24);
    }
    unsigned char b[4];
    std::memcpy(b, &v, 4);
    chunk.insert(chunk.end(), b, b + 4);
  };
  auto putf = [&](float f) { put32(std::bit_cast<std::uint32_t>(f)); };
  auto flush = [&](bool force) {
    if (ok && (force || chunk.size() >= kChunk)) {
      ok = std::fwrite(chunk.data(), 1, chunk.size(), file) == chunk.size();
      chunk.clear();
    }
  };
  for (std::size_t i = 0; i < n && ok; ++i) {
    for (int k = 0; k < 3; ++k) putf(mesh.positions[i][k]);
    if (normals) {
      for (int k = 0; k < 3; ++k) putf(mesh.normals[i][k]);
    }
    if (uvs) {
      // PLY texture coordinates have t = 0 at the image bottom.
      putf(mesh.uvs[i].x());
      putf(1.0f - mesh.uvs[i].y());
    }
    flush(false);
  }
  for (std::size_t i = 0; i < mesh.triangles.size() && ok; ++i) {
    chunk.push_back(3);
    for (int k = 0; k < 3; ++k) put32(mesh.triangles[i][k]);
    flush(false);
  }
  flush(true);
  ok = (std::fflush(file) == 0) && ok;
  ok = (std::fclose(file) == 0) && ok;
  if (!ok) {
    std::remove(tmp.c_str());
    return failed("write failed (disk full?)");
  }
  std::error_code ec;
  fs::rename(tmp, path, ec);
  if (ec) {
    std::remove(tmp.c_str());
    return failed(fmt::format("cannot rename {}: {}", tmp, ec.message()));
  }
  return true;
}

}  // namespace rigc
