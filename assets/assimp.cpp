// OBJ and STL through Assimp: the node tree's triangle meshes, welded, with their materials and
// base-colour textures (embedded or files beside the model).
#include <assimp/config.h>
#include <assimp/material.h>
#include <assimp/postprocess.h>
#include <assimp/scene.h>

#include <algorithm>
#include <array>
#include <assimp/Importer.hpp>
#include <bit>
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>
#include <string>
#include <system_error>
#include <utility>
#include <vector>

#include "assets/model_loading.h"
#include "assets/textures.h"
#include "io/file_status.h"

namespace rigc::loading {
namespace {

namespace fs = std::filesystem;
using Eigen::Vector2f;
using Eigen::Vector3d;
using Eigen::Vector3f;
using ir::Mat4;

Mat4 to_mat4(const aiMatrix4x4& m) {
  Mat4 out;
  for (int r = 0; r < 4; ++r) {
    for (int c = 0; c < 4; ++c) out(r, c) = m[r][c];
  }
  return out;
}

// Converts a scene Assimp has read: its materials, then every mesh its node tree places.
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
      tex = embedded_texture(*embedded, reference);
    } else {
      const fs::path file = texture_file(reference, material);
      tex = decode_image(file.string(), read_file_bytes(file),
                         fmt::format("texture '{}'", file.string()));
    }
    out_->textures.push_back(std::move(tex));
    const int index = static_cast<int>(out_->textures.size() - 1);
    textures_[reference] = index;
    return index;
  }

  // A texture inside the model file: encoded bytes (mHeight 0) or mWidth x mHeight texels.
  ir::Texture embedded_texture(const aiTexture& embedded, const std::string& reference) const {
    const std::string what = fmt::format("embedded texture '{}'", reference);
    const std::string source = fmt::format("{}#{}", path_, reference);
    if (embedded.mHeight == 0) {
      const auto* bytes = reinterpret_cast<const unsigned char*>(embedded.pcData);
      return decode_image(source, std::vector<unsigned char>(bytes, bytes + embedded.mWidth), what);
    }
    std::vector<unsigned char> rgba(static_cast<std::size_t>(embedded.mWidth) * embedded.mHeight *
                                    4);
    for (std::size_t i = 0; i < rgba.size() / 4; ++i) {
      const aiTexel& t = embedded.pcData[i];
      rgba[4 * i + 0] = t.r;
      rgba[4 * i + 1] = t.g;
      rgba[4 * i + 2] = t.b;
      rgba[4 * i + 3] = t.a;
    }
    return make_texture(source, static_cast<int>(embedded.mWidth),
                        static_cast<int>(embedded.mHeight), 4, 8, rgba, what);
  }

  // The image file a material names, relative to the model's folder, or else beside the model.
  // Paths written on Windows use backslashes.
  fs::path texture_file(const std::string& reference, const std::string& material) const {
    std::string clean = reference;
    std::replace(clean.begin(), clean.end(), '\\', '/');
    const fs::path dir = fs::path(path_).parent_path();
    fs::path file = fs::path(clean).is_absolute() ? fs::path(clean) : dir / clean;
    if (names_nothing(file)) {
      const fs::path beside = dir / fs::path(clean).filename();
      if (names_nothing(beside)) {
        fail("texture '{}' of material '{}' not found (looked for {})", reference, material,
             file.lexically_normal().string());
      }
      file = beside;
    }
    if (const std::string why = why_not_readable(file); !why.empty()) {
      fail("texture '{}' of material '{}': {} {}", reference, material,
           file.lexically_normal().string(), why);
    }
    return file.lexically_normal();
  }

  void add_mesh(const aiMesh& mesh, const Mat4& world) {
    if (!(mesh.mPrimitiveTypes & aiPrimitiveType_TRIANGLE) || mesh.mNumFaces == 0 ||
        !mesh.mVertices) {
      return;
    }
    const Placement placement(world);
    const int material =
        mesh.mMaterialIndex < out_->materials.size() ? static_cast<int>(mesh.mMaterialIndex) : 0;
    check_positions(mesh);
    const aiVector3D* file_normals = use_file_normals_ ? mesh.mNormals : nullptr;
    const aiVector3D* uvs = mesh.mTextureCoords[0];
    // OBJ and STL give every triangle corner its own vertex: weld the identical ones.
    std::vector<std::uint32_t> remap, keep;
    weld_identical(mesh, file_normals, uvs, &remap, &keep);
    const std::uint32_t base = copy_vertices(mesh, keep, file_normals, uvs, placement);
    builder_.reserve_triangles(mesh.mNumFaces);
    for (unsigned f = 0; f < mesh.mNumFaces; ++f) {
      const aiFace& face = mesh.mFaces[f];
      if (face.mNumIndices != 3) continue;
      for (unsigned k = 0; k < 3; ++k) {
        if (face.mIndices[k] >= mesh.mNumVertices) {
          fail("mesh '{}' face {} index {} is out of range ({} vertices)", mesh.mName.C_Str(), f,
               face.mIndices[k], mesh.mNumVertices);
        }
      }
      builder_.add_triangle(base + remap[face.mIndices[0]], base + remap[face.mIndices[1]],
                            base + remap[face.mIndices[2]], material, placement.flip);
    }
  }

  static void check_positions(const aiMesh& mesh) {
    for (std::uint32_t i = 0; i < mesh.mNumVertices; ++i) {
      const aiVector3D& v = mesh.mVertices[i];
      if (!std::isfinite(v.x) || !std::isfinite(v.y) || !std::isfinite(v.z)) {
        fail("mesh '{}' vertex {} has a position that is not finite ({}, {}, {})",
             mesh.mName.C_Str(), i, v.x, v.y, v.z);
      }
    }
  }

  // Appends the vertices `keep` lists, placed in the world; returns the index of the first. A
  // mesh without normals, or with a broken one, gets all its normals computed.
  std::uint32_t copy_vertices(const aiMesh& mesh, const std::vector<std::uint32_t>& keep,
                              const aiVector3D* file_normals, const aiVector3D* uvs,
                              const Placement& placement) {
    const std::uint32_t base = builder_.add_vertices(keep.size());
    bool has_normals = file_normals != nullptr && placement.normals_ok;
    for (std::uint32_t k = 0; k < keep.size(); ++k) {
      const std::uint32_t i = keep[k];
      const aiVector3D& v = mesh.mVertices[i];
      builder_.position(base + k) = placement.linear * Vector3f(v.x, v.y, v.z) + placement.offset;
      if (has_normals) {
        const aiVector3D& an = file_normals[i];
        const Vector3f nn = placement.to_normal * Vector3f(an.x, an.y, an.z);
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
    return base;
  }

  // Maps every vertex to the first one with bit-identical position (and normal and uv, when they
  // are used): remap[vertex] indexes `keep`, which lists the vertices kept. Assimp's
  // JoinIdenticalVertices does the same, far more slowly on large meshes.
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
  MeshBuilder builder_;
  std::map<std::string, int> textures_;
};

// The material libraries an OBJ names (`mtllib a.mtl b.mtl`), relative to its folder.
std::vector<std::string> material_libraries(const std::string& path) {
  std::vector<std::string> names;
  std::ifstream in(path, std::ios::binary);
  std::string line;
  while (std::getline(in, line)) {
    const std::size_t start = line.find_first_not_of(" \t");
    if (start == std::string::npos || line.compare(start, 7, "mtllib ") != 0) continue;
    std::istringstream words(line.substr(start + 7));
    std::string name;
    while (words >> name) names.push_back(name);
  }
  return names;
}

// A material library that is there but not a file (a folder, a device) fails: Assimp says only
// "File read error". One that is missing is a warning: Assimp loads the mesh without it and says
// nothing, so its colours and textures would be lost silently.
std::vector<std::string> check_material_libraries(const std::string& path) {
  std::vector<std::string> warnings;
  for (const std::string& name : material_libraries(path)) {
    const fs::path file = fs::path(path).parent_path() / name;
    std::error_code ec;
    const fs::file_status status = fs::status(file, ec);
    if (status.type() == fs::file_type::not_found || (ec && !fs::exists(status))) {
      warnings.push_back(fmt::format(
          "material library '{}' is not beside the mesh: its colours and textures are not used",
          one_line(name)));
    } else if (fs::is_directory(status)) {
      fail("material library '{}' (mtllib) is a folder, not a file", one_line(name));
    } else if (!fs::is_regular_file(status)) {
      fail("material library '{}' (mtllib) is not a regular file", one_line(name));
    }
  }
  return warnings;
}

// Assimp's message in the user's terms: its validation of its own data structure speaks of
// aiScene fields, and its STL reader of "storage representation".
std::string assimp_message(const std::string& raw) {
  const std::string message = one_line(raw);
  auto has = [&](const char* text) { return message.find(text) != std::string::npos; };
  if (message.empty()) return "could not be read (the importer gave no reason)";
  if (has("mNumMeshes is 0") || has("contains no vertices") || has("contains no faces")) {
    return "contains no triangles (no faces, or faces without vertices)";
  }
  if (has("is too small")) return "is too small to hold a mesh";
  if (has("Failed to determine STL storage representation")) {
    return "is neither a binary STL (its size disagrees with its triangle count) nor an ASCII "
           "STL (starting with 'solid')";
  }
  const std::string prefix = "Validation failed: ";
  if (message.rfind(prefix, 0) == 0) return "is malformed: " + message.substr(prefix.size());
  return "could not be read: " + message;
}

}  // namespace

LoadedModel load_with_assimp(const std::string& path, const std::string& ext) {
  LoadedModel out;
  Assimp::Importer importer;
  // No JoinIdenticalVertices (slow): AssimpLoader welds vertices itself.
  const unsigned flags =
      aiProcess_Triangulate | aiProcess_SortByPType | aiProcess_ValidateDataStructure;
  const aiScene* scene = nullptr;
  if (ext == ".stl") {
    StlFile stl = check_stl(path);
    out.warnings = std::move(stl.warnings);
    scene = importer.ReadFileFromMemory(stl.bytes.data(), stl.bytes.size(), flags, "stl");
  } else {
    out.warnings = check_material_libraries(path);
    scene = importer.ReadFile(path, flags);
  }
  if (!scene) fail("{}", assimp_message(importer.GetErrorString()));
  if (scene->mFlags & AI_SCENE_FLAGS_INCOMPLETE) fail("is incomplete (no meshes were read)");
  AssimpLoader(path, *scene, /*use_file_normals=*/ext != ".stl", &out).run();
  return out;
}

}  // namespace rigc::loading
