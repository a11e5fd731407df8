// PLY: the native reader through load_model (assets/ply.cpp), and write_ply.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <cstring>
#include <string>

#include "assets/model_test_support.h"
#include "assets/primitives.h"
#include "tests/test_support.h"

namespace rigc::model_testing {
namespace {

using ::rigc::testing::TempDir;

TEST(MeshIoPly, LoadsAsciiAndBinaryCubes) {
  for (const std::string name : {"PLY/cube.ply", "PLY/cube_binary.ply"}) {
    SCOPED_TRACE(name);
    const LoadedModel m = load_ok(kModels + name);
    expect_consistent(m);
    EXPECT_EQ(m.mesh.triangles.size(), 12u);
    EXPECT_EQ(m.mesh.positions.size(), 8u);
    Vector3f lo, hi;
    bounds(m.mesh, &lo, &hi);
    EXPECT_TRUE(lo.isApprox(Vector3f(0, 0, 0)));
    EXPECT_TRUE(hi.isApprox(Vector3f(1, 1, 1)));
    expect_outward(m.mesh, Vector3f(0.5f, 0.5f, 0.5f));
  }
}

TEST(MeshIoPly, LoadsNormalsAndUvs) {
  const LoadedModel m = load_ok(kModels + "PLY/cube_uv.ply");
  expect_consistent(m);
  EXPECT_EQ(m.mesh.triangles.size(), 12u);
  EXPECT_EQ(m.mesh.positions.size(), 24u);
  ASSERT_EQ(m.mesh.uvs.size(), 24u);
  expect_unit_box(m.mesh, 1.0f);
  expect_outward(m.mesh);
  const LoadedModel wuson = load_ok(kModels + "PLY/Wuson.ply");
  expect_consistent(wuson);
  EXPECT_EQ(wuson.mesh.triangles.size(), 3732u);
  EXPECT_FALSE(wuson.mesh.uvs.empty());
}

TEST(MeshIoPly, RejectsMalformedFiles) {
  expect_load_error(kModels + "PLY/points.ply", "contains no triangles");
  expect_load_error(kModels + "PLY/pond.0.ply", "more than the file holds");
  expect_load_error(kModels + "PLY/issue623.ply", "list");

  TempDir dir;
  const std::string header =
      "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
      "property float z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n";
  write_file(dir.file("range.ply"), header + "0 0 0\n1 0 0\n0 1 0\n3 0 1 7\n");
  expect_load_error(dir.file("range.ply"), "index 7 is out of range (3 vertices)");
  write_file(dir.file("nan.ply"), header + "0 0 0\n1 nan 0\n0 1 0\n3 0 1 2\n");
  expect_load_error(dir.file("nan.ply"), "not finite");
  // Collinear corners: a triangle with no area (coverage printed -nan, eval's sampler threw).
  write_file(dir.file("flat.ply"), header + "0 0 0\n1 1 1\n2 2 2\n3 0 1 2\n");
  expect_load_error(dir.file("flat.ply"),
                    "has no triangle with an area (all 1 are lines or points)");
  write_file(dir.file("short.ply"), header + "0 0 0\n1 0 0\n");
  expect_load_error(dir.file("short.ply"), "truncated");
  write_file(dir.file("huge.ply"),
             "ply\nformat binary_little_endian 1.0\nelement vertex 4000000000\nproperty float x\n"
             "property float y\nproperty float z\nend_header\n");
  expect_load_error(dir.file("huge.ply"), "more than the file holds");
  write_file(dir.file("magic.ply"), "not a ply\n");
  expect_load_error(dir.file("magic.ply"), "not a PLY file");
}

TEST(MeshIoPly, ATextureFileThatIsAFolderSaysSo) {
  TempDir dir;
  write_file(dir.file("tex.ply"),
             "ply\nformat ascii 1.0\ncomment TextureFile tex.png\nelement vertex 3\n"
             "property float x\nproperty float y\nproperty float z\nelement face 1\n"
             "property list uchar int vertex_indices\nend_header\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n");
  fs::create_directory(dir.file("tex.png"));
  expect_load_error(dir.file("tex.ply"), "tex.png' is a folder");
  fs::remove(dir.file("tex.png"));
  fs::create_symlink("/dev/zero", dir.file("tex.png"));
  expect_load_error(dir.file("tex.ply"), "tex.png' is not a regular file");
}

TEST(MeshIoPly, ReadsBigEndianAndPolygons) {
  TempDir dir;
  std::string bytes =
      "ply\nformat binary_big_endian 1.0\ncomment a unit square as one quad\n"
      "element vertex 4\nproperty double x\nproperty double y\nproperty double z\n"
      "element face 1\nproperty list uchar ushort vertex_index\nend_header\n";
  auto put_be = [&](const void* p, std::size_t n) {
    for (std::size_t i = n; i-- > 0;) bytes.push_back(static_cast<const char*>(p)[i]);
  };
  const double xy[4][2] = {{0, 0}, {1, 0}, {1, 1}, {0, 1}};
  for (const auto& v : xy) {
    const double z = 0;
    put_be(&v[0], 8);
    put_be(&v[1], 8);
    put_be(&z, 8);
  }
  bytes.push_back(4);
  for (std::uint16_t i = 0; i < 4; ++i) put_be(&i, 2);
  write_file(dir.file("quad.ply"), bytes);
  const LoadedModel m = load_ok(dir.file("quad.ply"));
  expect_consistent(m);
  EXPECT_EQ(m.mesh.triangles.size(), 2u);
  EXPECT_TRUE(m.mesh.positions[2].isApprox(Vector3f(1, 1, 0)));
  EXPECT_TRUE(m.mesh.normals[0].isApprox(Vector3f(0, 0, 1)));
}

TEST(MeshIoWritePly, RoundTripPreservesTheMesh) {
  TempDir dir;
  const ir::Mesh mesh = make_primitive(PrimitiveKind::kStatue, 3, 5);
  std::string error;
  ASSERT_TRUE(write_ply(dir.file("statue.ply"), mesh, &error)) << error;
  // Only the file itself is left in the folder: no temporary beside it.
  std::vector<std::string> entries;
  for (const auto& entry : fs::directory_iterator(dir.path())) {
    entries.push_back(entry.path().filename().string());
  }
  EXPECT_EQ(entries, std::vector<std::string>{"statue.ply"});
  const LoadedModel m = load_ok(dir.file("statue.ply"));
  expect_consistent(m);
  ASSERT_EQ(m.mesh.triangles, mesh.triangles);
  ASSERT_EQ(m.mesh.positions.size(), mesh.positions.size());
  ASSERT_EQ(m.mesh.uvs.size(), mesh.uvs.size());
  for (std::size_t i = 0; i < mesh.positions.size(); ++i) {
    ASSERT_EQ(m.mesh.positions[i], mesh.positions[i]) << i;
    ASSERT_TRUE(m.mesh.normals[i].isApprox(mesh.normals[i], 1e-5f)) << i;
    ASSERT_NEAR(m.mesh.uvs[i].x(), mesh.uvs[i].x(), 1e-6f);
    ASSERT_NEAR(m.mesh.uvs[i].y(), mesh.uvs[i].y(), 1e-6f);
  }
}

TEST(MeshIoWritePly, WithoutNormalsOrUvsNormalsAreComputed) {
  TempDir dir;
  ir::Mesh mesh = make_primitive(PrimitiveKind::kSphere, 2, 1);
  mesh.normals.clear();
  mesh.uvs.clear();
  std::string error;
  ASSERT_TRUE(write_ply(dir.file("sphere.ply"), mesh, &error)) << error;
  const LoadedModel m = load_ok(dir.file("sphere.ply"));
  expect_consistent(m);
  EXPECT_EQ(m.mesh.triangles.size(), mesh.triangles.size());
  EXPECT_TRUE(m.mesh.uvs.empty());
  for (std::size_t i = 0; i < m.mesh.positions.size(); ++i) {
    EXPECT_GT(m.mesh.normals[i].dot(m.mesh.positions[i].normalized()), 0.99f);
  }
}

TEST(MeshIoWritePly, VertexColoursComeBackAsTheLinearColoursWritten) {
  TempDir dir;
  ir::Mesh mesh = make_primitive(PrimitiveKind::kSphere, 2, 1);
  for (std::size_t i = 0; i < mesh.positions.size(); ++i) {
    mesh.colors.emplace_back(0.02f * static_cast<float>(i % 50), 0.5f, 1.0f);
  }
  std::string error;
  ASSERT_TRUE(write_ply(dir.file("sphere.ply"), mesh, &error)) << error;
  const LoadedModel m = load_ok(dir.file("sphere.ply"));
  ASSERT_EQ(m.vertex_colors.size(), mesh.colors.size());
  for (std::size_t i = 0; i < mesh.colors.size(); ++i) {
    // 8-bit sRGB holds a linear value to within half a step of its encoding.
    ASSERT_TRUE(m.vertex_colors[i].isApprox(mesh.colors[i], 0.01f) ||
                (m.vertex_colors[i] - mesh.colors[i]).cwiseAbs().maxCoeff() < 0.003f)
        << i << ": " << m.vertex_colors[i].transpose() << " against " << mesh.colors[i].transpose();
  }
}

TEST(MeshIoWritePly, ReportsFailures) {
  const ir::Mesh mesh = make_primitive(PrimitiveKind::kBox, 1, 1);
  std::string error;
  EXPECT_FALSE(write_ply("/nonexistent-dir/x/box.ply", mesh, &error));
  EXPECT_EQ(error.rfind("cannot write /nonexistent-dir/x/box.ply: ", 0), 0u) << error;
  ir::Mesh bad = mesh;
  bad.triangles.push_back({0, 1, 99});
  TempDir dir;
  EXPECT_FALSE(write_ply(dir.file("bad.ply"), bad, &error));
  EXPECT_FALSE(fs::exists(dir.file("bad.ply")));
}

}  // namespace
}  // namespace rigc::model_testing
