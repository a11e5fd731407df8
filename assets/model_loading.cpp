#include "assets/model_loading.h"

#include <bit>
#include <cctype>
#include <cmath>
#include <fstream>
#include <unordered_map>

namespace rigc::loading {

using Eigen::Matrix3d;
using Eigen::Vector2f;
using Eigen::Vector3f;

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

std::string cut_long_words(const std::string& text) {
  std::string out;
  std::size_t start = 0;
  while (start < text.size()) {
    const std::size_t space = text.find(' ', start);
    const std::size_t end = space == std::string::npos ? text.size() : space;
    if (end - start > kLongestWord) {
      out.append(text, start, 60);
      out += fmt::format("... ({} characters)", end - start);
    } else {
      out.append(text, start, end - start);
    }
    if (space != std::string::npos) out += ' ';
    start = end + 1;
  }
  return out;
}

std::string lower(std::string s) {
  for (char& c : s) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return s;
}

std::vector<unsigned char> read_file_bytes(const std::filesystem::path& path) {
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

Matrix3d normal_matrix(const Matrix3d& linear, bool* ok) {
  const double det = linear.determinant();
  *ok = std::isfinite(det) && std::abs(det) > 1e-300;
  if (!*ok) return Matrix3d::Identity();
  return linear.inverse().transpose();
}

std::uint32_t MeshBuilder::add_vertices(std::size_t n) {
  ir::Mesh& m = model_->mesh;
  const std::size_t base = m.positions.size();
  if (n > kMaxVertices - base) fail("has too many vertices (more than {})", kMaxVertices);
  m.positions.resize(base + n, Vector3f::Zero());
  m.normals.resize(base + n, Vector3f::Zero());
  m.uvs.resize(base + n, Vector2f::Zero());
  needs_normal_.resize(base + n, 0);
  if (!model_->vertex_colors.empty()) model_->vertex_colors.resize(base + n, Vector3f::Ones());
  return static_cast<std::uint32_t>(base);
}

void MeshBuilder::add_colors() {
  model_->vertex_colors.resize(model_->mesh.positions.size(), Vector3f::Ones());
}

void MeshBuilder::reserve_triangles(std::size_t n) {
  ir::Mesh& m = model_->mesh;
  if (n > kMaxTriangles - m.triangles.size()) {
    fail("has too many triangles (more than {})", kMaxTriangles);
  }
  m.triangles.reserve(m.triangles.size() + n);
  m.triangle_material.reserve(m.triangles.size() + n);
}

void MeshBuilder::finish() {
  ir::Mesh& m = model_->mesh;
  if (m.triangles.empty()) fail("contains no triangles");
  for (std::size_t i = 0; i < m.positions.size(); ++i) {
    if (!m.positions[i].allFinite()) fail("vertex {} has a position that is not finite", i);
  }
  // A mesh of lines and points only has no surface to see or measure: nothing would render, and
  // coverage and eval have no area to work with.
  const bool any_area = std::any_of(m.triangles.begin(), m.triangles.end(), [&](const auto& t) {
    const Eigen::Vector3d p0 = m.positions[t[0]].template cast<double>();
    const Eigen::Vector3d e1 = m.positions[t[1]].template cast<double>() - p0;
    const Eigen::Vector3d e2 = m.positions[t[2]].template cast<double>() - p0;
    return e1.cross(e2).squaredNorm() > 0;
  });
  if (!any_area)
    fail("has no triangle with an area (all {} are lines or points)", m.triangles.size());
  orient_outward();
  compute_missing_normals();
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
  if (!model_->vertex_colors.empty()) set_base_colors_from_vertices();
}

void MeshBuilder::set_base_colors_from_vertices() {
  const ir::Mesh& m = model_->mesh;
  const std::vector<Vector3f>& colors = model_->vertex_colors;
  std::vector<Eigen::Vector3d> sum(model_->materials.size(), Eigen::Vector3d::Zero());
  std::vector<double> area(model_->materials.size(), 0.0);
  for (std::size_t f = 0; f < m.triangles.size(); ++f) {
    const auto& t = m.triangles[f];
    const Eigen::Vector3d p0 = m.positions[t[0]].cast<double>();
    const double a =
        (m.positions[t[1]].cast<double>() - p0).cross(m.positions[t[2]].cast<double>() - p0).norm();
    const Eigen::Vector3d mean = (colors[t[0]] + colors[t[1]] + colors[t[2]]).cast<double>() / 3;
    sum[m.triangle_material[f]] += a * mean;
    area[m.triangle_material[f]] += a;
  }
  for (std::size_t i = 0; i < model_->materials.size(); ++i) {
    if (area[i] > 0) model_->materials[i].base_color = sum[i] / area[i];
  }
}

namespace {

// Each vertex's first vertex at the same position (files that split corners for their normals or
// uvs still share positions along an edge).
std::vector<std::uint32_t> same_position_ids(const std::vector<Vector3f>& positions) {
  std::unordered_map<std::uint64_t, std::vector<std::uint32_t>> buckets;
  std::vector<std::uint32_t> ids(positions.size());
  auto bits = [](float f) {
    return static_cast<std::uint64_t>(std::bit_cast<std::uint32_t>(f + 0.0f));
  };
  for (std::uint32_t i = 0; i < positions.size(); ++i) {
    const Vector3f& p = positions[i];
    const std::uint64_t key = (bits(p.x()) * 0x9e3779b97f4a7c15ULL) ^
                              (bits(p.y()) * 0xc2b2ae3d27d4eb4fULL) ^ (bits(p.z()) << 1);
    auto& bucket = buckets[key];
    ids[i] = i;
    for (std::uint32_t j : bucket) {
      if (positions[j] == p) {
        ids[i] = j;
        break;
      }
    }
    if (ids[i] == i) bucket.push_back(i);
  }
  return ids;
}

// Whether the triangles close a surface wound consistently: every edge is met once in each
// direction.
bool closed_and_consistent(const ir::Mesh& m, const std::vector<std::uint32_t>& id) {
  std::unordered_map<std::uint64_t, int> directed;
  directed.reserve(m.triangles.size() * 3);
  auto key = [](std::uint32_t a, std::uint32_t b) { return std::uint64_t{a} << 32 | b; };
  for (const auto& t : m.triangles) {
    for (int k = 0; k < 3; ++k) {
      const std::uint32_t a = id[t[k]], b = id[t[(k + 1) % 3]];
      if (a == b) return false;
      if (++directed[key(a, b)] > 1) return false;
    }
  }
  for (const auto& [edge, count] : directed) {
    if (!directed.contains(
            key(static_cast<std::uint32_t>(edge), static_cast<std::uint32_t>(edge >> 32)))) {
      return false;
    }
  }
  return true;
}

// The volume a closed mesh encloses, negative when its triangles face inward.
double signed_volume(const ir::Mesh& m) {
  double volume = 0;
  for (const auto& t : m.triangles) {
    const Eigen::Vector3d a = m.positions[t[0]].cast<double>();
    volume += a.dot(m.positions[t[1]].cast<double>().cross(m.positions[t[2]].cast<double>()));
  }
  return volume / 6;
}

}  // namespace

// A closed mesh whose every face is wound inward (its signed volume negative) renders like the
// right one in two-sided renderers, but coverage then finds every face turned away from every
// camera. It is turned the right way out, with a warning. The file's normals are turned too when
// they followed the winding.
void MeshBuilder::orient_outward() {
  ir::Mesh& m = model_->mesh;
  if (!closed_and_consistent(m, same_position_ids(m.positions)) || !(signed_volume(m) < 0)) return;
  double agreement = 0;  // > 0: the file's normals point the way the triangles are wound
  for (const auto& t : m.triangles) {
    const Vector3f& p0 = m.positions[t[0]];
    const Vector3f face = (m.positions[t[1]] - p0).cross(m.positions[t[2]] - p0);
    for (std::uint32_t v : t) {
      if (!needs_normal_[v]) agreement += face.dot(m.normals[v]);
    }
  }
  for (auto& t : m.triangles) std::swap(t[1], t[2]);
  if (agreement > 0) {
    for (std::size_t v = 0; v < m.normals.size(); ++v) {
      if (!needs_normal_[v]) m.normals[v] = -m.normals[v];
    }
  }
  model_->warnings.push_back(
      "the faces are wound inside out (their normals point into the closed mesh: its signed "
      "volume is negative); they were turned outward");
}

// Sums the (area-weighted) face normals into the vertices that need one; finish() normalises.
void MeshBuilder::compute_missing_normals() {
  ir::Mesh& m = model_->mesh;
  if (std::find(needs_normal_.begin(), needs_normal_.end(), 1) == needs_normal_.end()) return;
  for (const auto& t : m.triangles) {
    if (!needs_normal_[t[0]] && !needs_normal_[t[1]] && !needs_normal_[t[2]]) continue;
    const Vector3f& p0 = m.positions[t[0]];
    const Vector3f n = (m.positions[t[1]] - p0).cross(m.positions[t[2]] - p0);
    for (std::uint32_t v : t) {
      if (needs_normal_[v]) m.normals[v] += n;
    }
  }
}

}  // namespace rigc::loading
