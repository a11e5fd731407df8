// What the model-file readers share (internal to assets/): the error they throw, the mesh they
// build, and the entry point of each format. load_model (mesh_io.cpp) picks the reader by the
// file's extension and turns a LoadError into its one-line message.
#pragma once

#include <fmt/format.h>

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <limits>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "assets/mesh_io.h"

namespace rigc::loading {

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
std::string one_line(const std::string& text);

// `text` with every word (a run without spaces) longer than kLongestWord cut to its first 60
// characters and "...": libraries echo whole data URIs (megabytes of base64) in their messages.
inline constexpr std::size_t kLongestWord = 200;
std::string cut_long_words(const std::string& text);

std::string lower(std::string s);

// The whole file; a LoadError if it cannot be opened or read.
std::vector<unsigned char> read_file_bytes(const std::filesystem::path& path);

// The matrix that takes normals through `linear` (its inverse transpose); identity with *ok false
// when `linear` is singular.
Eigen::Matrix3d normal_matrix(const Eigen::Matrix3d& linear, bool* ok);

// A node's world matrix, ready to apply to vertex positions and normals.
struct Placement {
  explicit Placement(const ir::Mat4& world)
      : linear(world.topLeftCorner<3, 3>().cast<float>()),
        offset(world.topRightCorner<3, 1>().cast<float>()),
        to_normal(normal_matrix(world.topLeftCorner<3, 3>(), &normals_ok).cast<float>()),
        flip(world.topLeftCorner<3, 3>().determinant() < 0) {}

  Eigen::Matrix3f linear;
  Eigen::Vector3f offset;
  bool normals_ok = false;  // false: the matrix is singular, so normals are computed
  Eigen::Matrix3f to_normal;
  bool flip;  // the matrix mirrors, so the triangles' winding is reversed
};

// Appends vertices and triangles to a LoadedModel's mesh, and at the end computes the normals the
// file did not give.
class MeshBuilder {
 public:
  explicit MeshBuilder(LoadedModel* model) : model_(model) {}

  // Appends `n` vertices (positions, normals and uvs zeroed); returns the first index.
  std::uint32_t add_vertices(std::size_t n);

  void reserve_triangles(std::size_t n);

  // Gives every vertex a colour (white until set); finish() then sets each material's base
  // colour to the area-weighted mean of its triangles' vertex colours.
  void add_colors();
  Eigen::Vector3f& color(std::uint32_t i) { return model_->vertex_colors[i]; }

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

  Eigen::Vector3f& position(std::uint32_t i) { return model_->mesh.positions[i]; }
  Eigen::Vector3f& normal(std::uint32_t i) { return model_->mesh.normals[i]; }
  Eigen::Vector2f& uv(std::uint32_t i) { return model_->mesh.uvs[i]; }
  // Vertices first .. first + n - 1 get computed normals (their normals must be zero).
  void set_needs_normal(std::uint32_t first, std::size_t n) {
    std::fill_n(needs_normal_.begin() + first, n, 1);
  }
  void set_has_uvs() { has_uvs_ = true; }

  // Checks the result, turns a closed mesh wound inside out the right way (with a warning),
  // computes the normals the file did not give (area-weighted) and normalises.
  void finish();

 private:
  void compute_missing_normals();
  void orient_outward();
  void set_base_colors_from_vertices();

  LoadedModel* model_;
  std::vector<std::uint8_t> needs_normal_;
  bool has_uvs_ = false;
};

// An STL file's bytes as Assimp should read them, and what was mended on the way.
struct StlFile {
  std::vector<unsigned char> bytes;
  std::vector<std::string> warnings;
};

// Reads an STL and checks what Assimp does not: an ASCII STL must be whole (no facet cut short,
// an `endsolid` at the end); a binary STL's header count must match its size (when the body is
// whole triangles the count is mended, with a warning). Throws LoadError otherwise.
StlFile check_stl(const std::string& path);

// The format readers. Each throws LoadError on a malformed or unsupported file.
LoadedModel load_gltf(const std::string& path, bool binary);  // .gltf, or .glb when `binary`
LoadedModel load_ply(const std::string& path);
LoadedModel load_with_assimp(const std::string& path, const std::string& ext);  // .obj, .stl

}  // namespace rigc::loading
