#include "assets/primitives.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <map>
#include <tuple>

namespace rigc {
namespace {

using Eigen::Vector3d;
using Eigen::Vector3f;

// Welds vertices with bit-identical positions, so meshes with uv seams or flat-shaded corners can
// be checked for closedness.
std::vector<std::uint32_t> weld(const ir::Mesh& mesh) {
  std::map<std::tuple<float, float, float>, std::uint32_t> ids;
  std::vector<std::uint32_t> out(mesh.positions.size());
  for (std::size_t i = 0; i < mesh.positions.size(); ++i) {
    const Vector3f& p = mesh.positions[i];
    out[i] = ids.try_emplace({p.x(), p.y(), p.z()}, static_cast<std::uint32_t>(ids.size()))
                 .first->second;
  }
  return out;
}

// Every undirected edge is used exactly twice, once in each direction (closed and consistently
// oriented). Returns the number of bad edges.
int bad_edges(const ir::Mesh& mesh) {
  const std::vector<std::uint32_t> id = weld(mesh);
  std::map<std::pair<std::uint32_t, std::uint32_t>, int> directed;
  for (const auto& t : mesh.triangles) {
    for (int k = 0; k < 3; ++k) ++directed[{id[t[k]], id[t[(k + 1) % 3]]}];
  }
  int bad = 0;
  for (const auto& [edge, count] : directed) {
    const auto reverse = directed.find({edge.second, edge.first});
    if (count != 1 || reverse == directed.end() || reverse->second != 1) ++bad;
  }
  return bad;
}

double signed_volume(const ir::Mesh& mesh) {
  double v = 0;
  for (const auto& t : mesh.triangles) {
    const Vector3d a = mesh.positions[t[0]].cast<double>();
    const Vector3d b = mesh.positions[t[1]].cast<double>();
    const Vector3d c = mesh.positions[t[2]].cast<double>();
    v += a.dot(b.cross(c)) / 6.0;
  }
  return v;
}

void expect_well_formed(const ir::Mesh& mesh) {
  const std::size_t n = mesh.positions.size();
  ASSERT_GT(n, 0u);
  ASSERT_EQ(mesh.normals.size(), n);
  ASSERT_EQ(mesh.uvs.size(), n);
  ASSERT_EQ(mesh.triangle_material.size(), mesh.triangles.size());
  std::vector<bool> used(n, false);
  for (const auto& t : mesh.triangles) {
    for (std::uint32_t i : t) {
      ASSERT_LT(i, n);
      used[i] = true;
    }
  }
  EXPECT_EQ(std::count(used.begin(), used.end(), false), 0) << "unreferenced vertices";
  for (std::int32_t m : mesh.triangle_material) EXPECT_EQ(m, 0);
  for (std::size_t i = 0; i < n; ++i) {
    ASSERT_TRUE(mesh.positions[i].allFinite());
    ASSERT_NEAR(mesh.normals[i].norm(), 1.0f, 1e-4f) << "vertex " << i;
    ASSERT_TRUE(mesh.uvs[i].allFinite());
    EXPECT_GE(mesh.uvs[i].y(), 0.0f);
    EXPECT_LE(mesh.uvs[i].y(), 1.0f);
  }
}

// Fraction of vertices whose normal points away from the centroid.
double outward_fraction(const ir::Mesh& mesh) {
  Vector3f centroid = Vector3f::Zero();
  for (const Vector3f& p : mesh.positions) centroid += p;
  centroid /= static_cast<float>(mesh.positions.size());
  std::size_t out = 0;
  for (std::size_t i = 0; i < mesh.positions.size(); ++i) {
    if (mesh.normals[i].dot(mesh.positions[i] - centroid) > 0) ++out;
  }
  return static_cast<double>(out) / mesh.positions.size();
}

// Fraction of triangles whose winding normal agrees with their vertex normals.
double winding_agreement(const ir::Mesh& mesh) {
  std::size_t agree = 0;
  for (const auto& t : mesh.triangles) {
    const Vector3f& a = mesh.positions[t[0]];
    const Vector3f face = (mesh.positions[t[1]] - a).cross(mesh.positions[t[2]] - a);
    const Vector3f vn = mesh.normals[t[0]] + mesh.normals[t[1]] + mesh.normals[t[2]];
    if (face.dot(vn) > 0) ++agree;
  }
  return static_cast<double>(agree) / mesh.triangles.size();
}

void bounds(const ir::Mesh& mesh, Vector3f* lo, Vector3f* hi) {
  *lo = mesh.positions[0];
  *hi = mesh.positions[0];
  for (const Vector3f& p : mesh.positions) {
    *lo = lo->cwiseMin(p);
    *hi = hi->cwiseMax(p);
  }
}

TEST(PrimitiveNames, RoundTrip) {
  const std::vector<std::string> names = primitive_names();
  ASSERT_EQ(names.size(), 4u);
  for (const std::string& name : names) EXPECT_TRUE(primitive_from_name(name)) << name;
  EXPECT_EQ(primitive_from_name("sphere"), PrimitiveKind::kSphere);
  EXPECT_EQ(primitive_from_name("box"), PrimitiveKind::kBox);
  EXPECT_EQ(primitive_from_name("cylinder"), PrimitiveKind::kCylinder);
  EXPECT_EQ(primitive_from_name("statue"), PrimitiveKind::kStatue);
  EXPECT_FALSE(primitive_from_name("Sphere"));
  EXPECT_FALSE(primitive_from_name("cube"));
  EXPECT_FALSE(primitive_from_name(""));
}

TEST(PrimitiveSphere, ClosedOutwardAndRound) {
  for (int detail : {1, 3, 5}) {
    SCOPED_TRACE(detail);
    const ir::Mesh mesh = make_primitive(PrimitiveKind::kSphere, detail, 1);
    expect_well_formed(mesh);
    EXPECT_EQ(bad_edges(mesh), 0);
    EXPECT_EQ(outward_fraction(mesh), 1.0);
    EXPECT_EQ(winding_agreement(mesh), 1.0);
    for (const Vector3f& p : mesh.positions) ASSERT_NEAR(p.norm(), 0.5f, 1e-5f);
    const double exact = 4.0 / 3.0 * M_PI * 0.125;
    EXPECT_GT(signed_volume(mesh), 0.9 * exact);
    EXPECT_LT(signed_volume(mesh), exact);
  }
  EXPECT_EQ(make_primitive(PrimitiveKind::kSphere, 1, 1).triangles.size(), 320u);
}

TEST(PrimitiveSphere, UvsDoNotWrapAcrossTriangles) {
  const ir::Mesh mesh = make_primitive(PrimitiveKind::kSphere, 4, 1);
  for (const auto& t : mesh.triangles) {
    float lo = 10, hi = -10;
    for (std::uint32_t i : t) {
      lo = std::min(lo, mesh.uvs[i].x());
      hi = std::max(hi, mesh.uvs[i].x());
    }
    ASSERT_LT(hi - lo, 0.5f);
    ASSERT_GE(lo, 0.0f);
    ASSERT_LE(hi, 1.5f);
  }
  // The north pole (z = +0.5) is at the top of the image.
  for (std::size_t i = 0; i < mesh.positions.size(); ++i) {
    if (mesh.positions[i].z() > 0.4999f) {
      EXPECT_LT(mesh.uvs[i].y(), 0.01f);
    }
  }
}

TEST(PrimitiveBox, TwentyFourVerticesFlatNormals) {
  const ir::Mesh mesh = make_primitive(PrimitiveKind::kBox, 5, 1);
  expect_well_formed(mesh);
  EXPECT_EQ(mesh.positions.size(), 24u);
  EXPECT_EQ(mesh.triangles.size(), 12u);
  EXPECT_EQ(bad_edges(mesh), 0);
  EXPECT_EQ(winding_agreement(mesh), 1.0);
  EXPECT_NEAR(signed_volume(mesh), 1.0, 1e-6);
  for (std::size_t i = 0; i < 24; ++i) {
    // Flat: the normal is the face's axis, and the vertex lies on that face.
    EXPECT_NEAR(mesh.normals[i].dot(mesh.positions[i]), 0.5f, 1e-6f);
    EXPECT_NEAR(mesh.normals[i].cwiseAbs().maxCoeff(), 1.0f, 1e-6f);
    EXPECT_NEAR(mesh.positions[i].cwiseAbs().maxCoeff(), 0.5f, 1e-6f);
  }
  // Each face spans the whole texture.
  for (std::size_t f = 0; f < 6; ++f) {
    float area = 0;
    for (std::size_t k = 0; k < 2; ++k) {
      const auto& t = mesh.triangles[2 * f + k];
      const Eigen::Vector2f a = mesh.uvs[t[1]] - mesh.uvs[t[0]];
      const Eigen::Vector2f b = mesh.uvs[t[2]] - mesh.uvs[t[0]];
      area += std::abs(a.x() * b.y() - a.y() * b.x()) / 2;
    }
    EXPECT_NEAR(area, 1.0f, 1e-6f);
  }
}

TEST(PrimitiveCylinder, ClosedWithCaps) {
  for (int detail : {1, 4}) {
    SCOPED_TRACE(detail);
    const ir::Mesh mesh = make_primitive(PrimitiveKind::kCylinder, detail, 1);
    expect_well_formed(mesh);
    EXPECT_EQ(bad_edges(mesh), 0);
    EXPECT_EQ(outward_fraction(mesh), 1.0);
    EXPECT_EQ(winding_agreement(mesh), 1.0);
    Vector3f lo, hi;
    bounds(mesh, &lo, &hi);
    EXPECT_NEAR(lo.z(), -0.5f, 1e-6f);
    EXPECT_NEAR(hi.z(), 0.5f, 1e-6f);
    EXPECT_NEAR(hi.x(), 0.5f, 1e-6f);
    EXPECT_NEAR(lo.x(), -0.5f, 1e-6f);
    EXPECT_NEAR(signed_volume(mesh), M_PI * 0.25, 0.03);  // a 16-gon at detail 1
    // Cap vertices have axial normals, side vertices radial ones.
    for (std::size_t i = 0; i < mesh.positions.size(); ++i) {
      const Vector3f& n = mesh.normals[i];
      EXPECT_TRUE(std::abs(n.z()) < 1e-6f || std::abs(std::abs(n.z()) - 1.0f) < 1e-6f);
    }
  }
}

TEST(PrimitiveStatue, ClosedOutwardAboutOneMeterTall) {
  const ir::Mesh mesh = make_primitive(PrimitiveKind::kStatue, 5, 7);
  expect_well_formed(mesh);
  EXPECT_EQ(mesh.triangles.size(), 32000u);
  EXPECT_EQ(bad_edges(mesh), 0);
  EXPECT_GT(outward_fraction(mesh), 0.95);
  EXPECT_GT(winding_agreement(mesh), 0.97);
  EXPECT_GT(signed_volume(mesh), 0.05);  // a solid, not inside out
  Vector3f lo, hi;
  bounds(mesh, &lo, &hi);
  EXPECT_NEAR(hi.z() - lo.z(), 1.0f, 1e-5f);
  EXPECT_NEAR(hi.z() + lo.z(), 0.0f, 1e-5f);  // centred
  EXPECT_NEAR(hi.x() + lo.x(), 0.0f, 1e-5f);
  EXPECT_NEAR(hi.y() + lo.y(), 0.0f, 1e-5f);
  for (int axis : {0, 1}) {
    EXPECT_GT(hi[axis] - lo[axis], 0.35f);
    EXPECT_LT(hi[axis] - lo[axis], 0.8f);
  }
  // Rock-like: the surface is not a smooth ellipsoid, so the distance from the axis varies a lot
  // around a ring.
  double min_r = 1e9, max_r = 0;
  for (const Vector3f& p : mesh.positions) {
    if (std::abs(p.z()) < 0.02f) {
      min_r = std::min<double>(min_r, p.head<2>().norm());
      max_r = std::max<double>(max_r, p.head<2>().norm());
    }
  }
  EXPECT_GT(max_r / min_r, 1.15);
  // The flat base: many vertices at the very bottom with downward normals.
  int base = 0;
  for (std::size_t i = 0; i < mesh.positions.size(); ++i) {
    if (mesh.positions[i].z() < lo.z() + 1e-5f && mesh.normals[i].z() < -0.9f) ++base;
  }
  EXPECT_GT(base, 100);
}

TEST(PrimitiveStatue, DeterministicPerSeed) {
  const ir::Mesh a = make_primitive(PrimitiveKind::kStatue, 3, 42);
  const ir::Mesh b = make_primitive(PrimitiveKind::kStatue, 3, 42);
  const ir::Mesh c = make_primitive(PrimitiveKind::kStatue, 3, 43);
  ASSERT_EQ(a.positions.size(), b.positions.size());
  ASSERT_EQ(a.positions.size(), c.positions.size());
  EXPECT_EQ(0, std::memcmp(a.positions.data(), b.positions.data(),
                           a.positions.size() * sizeof(Vector3f)));
  EXPECT_EQ(a.triangles, b.triangles);
  double diff = 0;
  for (std::size_t i = 0; i < a.positions.size(); ++i) {
    diff = std::max<double>(diff, (a.positions[i] - c.positions[i]).norm());
  }
  EXPECT_GT(diff, 0.01);
}

// The shape for a seed is the same on every platform (integer hashing, no libm in the shape).
// These values change only when the statue's design is changed on purpose.
TEST(PrimitiveStatue, GoldenShape) {
  const ir::Mesh mesh = make_primitive(PrimitiveKind::kStatue, 2, 1);
  ASSERT_EQ(mesh.triangles.size(), 980u);
  double sum = 0;
  for (const Vector3f& p : mesh.positions) sum += p.cast<double>().norm();
  EXPECT_NEAR(sum, 186.662464, 1e-3);
  EXPECT_NEAR(mesh.positions[0].x(), -0.0057126f, 1e-6f);
  EXPECT_NEAR(mesh.positions[0].y(), -0.0034274f, 1e-6f);
  EXPECT_NEAR(mesh.positions[0].z(), 0.4710211f, 1e-6f);
}

TEST(PrimitiveStatue, TriangleCountsPerDetail) {
  // detail 6 is about 100k triangles, detail 8 over a million (for benchmarks).
  EXPECT_EQ(make_primitive(PrimitiveKind::kStatue, 6, 1).triangles.size(), 100820u);
  EXPECT_GE(make_primitive(PrimitiveKind::kStatue, 8, 1).triangles.size(), 1000000u);
  // Out-of-range details are clamped to 1..10.
  EXPECT_EQ(make_primitive(PrimitiveKind::kStatue, 0, 1).triangles.size(),
            make_primitive(PrimitiveKind::kStatue, 1, 1).triangles.size());
  EXPECT_EQ(make_primitive(PrimitiveKind::kSphere, -5, 1).triangles.size(), 320u);
}

}  // namespace
}  // namespace rigc
