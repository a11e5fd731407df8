// Model files in the forms scanners, archives and CAD tools write them (tests/meshes/, written
// by tests/meshes/make_meshes.py), through load_model.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <string>

#include "assets/model_test_support.h"
#include "tests/test_support.h"

using ::testing::HasSubstr;
using ::testing::Not;

namespace rigc::model_testing {
namespace {

using ::rigc::testing::read_text;
using ::rigc::testing::TempDir;

const std::string kMeshes = std::string(RIGC_SOURCE_DIR) + "/tests/meshes/";

bool has_warning(const LoadedModel& m, const std::string& text) {
  return std::any_of(m.warnings.begin(), m.warnings.end(),
                     [&](const std::string& w) { return w.find(text) != std::string::npos; });
}

TEST(RealWorldPly, TriangleStripsWithRestartsMakeTheCube) {
  const LoadedModel m = load_ok(kMeshes + "cube_tristrips.ply");
  expect_consistent(m);
  EXPECT_EQ(m.mesh.triangles.size(), 12u);
  expect_unit_box(m.mesh);
  expect_outward(m.mesh);  // the strips' alternating winding is undone
  EXPECT_TRUE(m.warnings.empty());
}

// Quads, big-endian, extra vertex properties (a list among them), an extra face property, an
// element to skip, and uchar colours: red on top, blue below, so the mean is half of each.
TEST(RealWorldPly, BigEndianQuadsWithExtraPropertiesAndVertexColours) {
  const LoadedModel m = load_ok(kMeshes + "cube_quads_big_endian_colors.ply");
  expect_consistent(m);
  EXPECT_EQ(m.mesh.triangles.size(), 12u);
  expect_unit_box(m.mesh);
  expect_outward(m.mesh);
  ASSERT_EQ(m.vertex_colors.size(), m.mesh.positions.size());
  for (std::size_t i = 0; i < m.mesh.positions.size(); ++i) {
    const Eigen::Vector3f expected =
        m.mesh.positions[i].z() > 0 ? Eigen::Vector3f(1, 0, 0) : Eigen::Vector3f(0, 0, 1);
    EXPECT_TRUE(m.vertex_colors[i].isApprox(expected)) << m.vertex_colors[i].transpose();
  }
  ASSERT_EQ(m.materials.size(), 1u);
  EXPECT_TRUE(m.materials[0].base_color.isApprox(Eigen::Vector3d(0.5, 0, 0.5), 1e-6))
      << m.materials[0].base_color.transpose();
}

// Hexagons and quads, float colours in sRGB (0.5 is 0.214 linear).
TEST(RealWorldPly, PolygonsAreTriangulatedAndFloatColoursLinearised) {
  const LoadedModel m = load_ok(kMeshes + "prism_polygons.ply");
  expect_consistent(m);
  EXPECT_EQ(m.mesh.triangles.size(), 2u * 4 + 6 * 2);
  expect_outward(m.mesh);
  ASSERT_EQ(m.vertex_colors.size(), m.mesh.positions.size());
  EXPECT_NEAR(m.materials[0].base_color.x(), 0.214, 1e-3);
}

TEST(RealWorldObj, NegativeIndicesAndNGonsLoadAMissingLibraryWarns) {
  const LoadedModel m = load_ok(kMeshes + "prism_negative_ngons.obj");
  expect_consistent(m);
  EXPECT_EQ(m.mesh.triangles.size(), 2u * 4 + 6 * 2);
  expect_outward(m.mesh);
  EXPECT_TRUE(has_warning(m, "material library 'missing.mtl' is not beside the mesh"));
}

TEST(RealWorldObj, AMaterialLibraryThatIsAFolderIsAClearError) {
  TempDir dir;
  fs::create_directory(dir.path() / "library.mtl");
  const std::string obj = (dir.path() / "m.obj").string();
  write_file(obj, "mtllib library.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n");
  expect_load_error(obj, "material library 'library.mtl' (mtllib) is a folder, not a file");
}

TEST(RealWorldStl, AsciiAndBinaryWithAWrongCountLoadTheCube) {
  for (const char* name : {"cube_ascii.stl", "cube_ascii_empty_solid.stl",
                           "cube_binary_count_0.stl", "cube_binary_count_99.stl"}) {
    SCOPED_TRACE(name);
    const LoadedModel m = load_ok(kMeshes + name);
    expect_consistent(m);
    EXPECT_EQ(m.mesh.triangles.size(), 12u);
    EXPECT_EQ(m.mesh.positions.size(), 8u);
    expect_unit_box(m.mesh);
    expect_outward(m.mesh);
  }
  EXPECT_TRUE(has_warning(load_ok(kMeshes + "cube_binary_count_99.stl"),
                          "the header claims 99 triangles but the file holds 12"));
}

// Row 12: six of twelve facets and a seventh cut short loaded silently.
TEST(RealWorldStl, AnAsciiStlCutMidFacetIsAnError) {
  expect_load_error(kMeshes + "cube_ascii_cut.stl",
                    "is truncated: the ASCII STL ends inside the facet that starts at line 44 "
                    "(6 whole facets before it)");
  TempDir dir;
  const std::string between = (dir.path() / "between.stl").string();
  std::string text = read_text(kMeshes + "cube_ascii.stl");
  write_file(between, text.substr(0, text.find("endsolid")));
  expect_load_error(between, "ends after 12 facets without 'endsolid'");
}

// Assimp's own words ("aiScene::mNumMeshes is 0", "Failed to determine STL storage
// representation") do not reach the user.
TEST(RealWorldMessages, AssimpInternalsAreSaidInTheUsersTerms) {
  TempDir dir;
  const auto file = [&](const std::string& name, const std::string& bytes) {
    const std::string path = (dir.path() / name).string();
    write_file(path, bytes);
    return path;
  };
  const std::string pad(64, '\n');
  expect_load_error(file("vertices.obj", "o thing\nv 0 0 0\nv 1 0 0\nv 1 1 1\n" + pad),
                    "contains no triangles");
  expect_load_error(file("empty.stl", "solid x\nendsolid x\n" + pad), "contains no triangles");
  expect_load_error(file("short.stl", std::string("\x01\x02hello", 7)),
                    "is not an STL file: too small for a binary STL (7 bytes)");
  std::string cut(84 + 50 * 3 - 7, '\0');
  cut[80] = 3;
  expect_load_error(file("cut.stl", cut),
                    "is truncated: its header claims 3 triangles (234 bytes) but the file has 227");
  for (const char* name : {"vertices.obj", "empty.stl", "short.stl", "cut.stl"}) {
    std::string error;
    EXPECT_FALSE(load_model((dir.path() / name).string(), &error));
    for (const char* internal :
         {"aiScene", "mNumMeshes", "storage representation", "Validation failed"}) {
      EXPECT_THAT(error, Not(HasSubstr(internal)));
    }
  }
}

// Row 11: a closed mesh wound inward is turned outward, with a warning; an open one is left.
TEST(RealWorldOrientation, ACubeWoundInwardIsTurnedOutwardWithAWarning) {
  const LoadedModel m = load_ok(kMeshes + "cube_inward.stl");
  expect_consistent(m);
  expect_outward(m.mesh);
  EXPECT_TRUE(has_warning(m, "the faces are wound inside out"));
  EXPECT_FALSE(has_warning(load_ok(kMeshes + "cube_ascii.stl"), "inside out"));
  TempDir dir;
  const std::string open = (dir.path() / "open.obj").string();
  // Two triangles of a box's floor, wound downward-facing-in: open, so nothing is inferred.
  write_file(open, "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 0 0 1\nf 1 3 2\nf 1 4 3\nf 1 2 5\n");
  EXPECT_FALSE(has_warning(load_ok(open), "inside out"));
}

}  // namespace
}  // namespace rigc::model_testing
