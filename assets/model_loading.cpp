#include "assets/model_loading.h"

#include <cctype>
#include <cmath>
#include <fstream>

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
  return static_cast<std::uint32_t>(base);
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
