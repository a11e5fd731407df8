#include "assets/mesh_io.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "assets/primitives.h"
#include "tests/test_support.h"

namespace rigc {
namespace {

namespace fs = std::filesystem;
using Eigen::Vector3f;
using ::rigc::testing::TempDir;

// The Debian package assimp-testmodels is a build dependency: a missing file is a failure.
const std::string kModels = "/usr/share/assimp/models/";

void write_file(const std::string& path, const std::string& bytes) {
  std::ofstream out(path, std::ios::binary);
  out.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
  ASSERT_TRUE(out.good()) << path;
}

template <typename T>
void append(std::string* out, const T& value) {
  out->append(reinterpret_cast<const char*>(&value), sizeof(T));
}

// Loads a model that must load; fails the test with the error otherwise.
LoadedModel load_ok(const std::string& path) {
  EXPECT_TRUE(fs::exists(path)) << path << " is missing (is assimp-testmodels installed?)";
  std::string error;
  std::optional<LoadedModel> model = load_model(path, &error);
  EXPECT_TRUE(model.has_value()) << error;
  return model ? std::move(*model) : LoadedModel{};
}

// Loading must fail with one line that starts with the path and contains `expected`.
void expect_load_error(const std::string& path, const std::string& expected) {
  SCOPED_TRACE(path);
  std::string error;
  const std::optional<LoadedModel> model = load_model(path, &error);
  EXPECT_FALSE(model.has_value());
  EXPECT_EQ(error.rfind(path + ": ", 0), 0u) << error;
  EXPECT_NE(error.find(expected), std::string::npos) << error;
  EXPECT_EQ(error.find('\n'), std::string::npos) << error;
}

// Structural invariants every loaded model satisfies.
void expect_consistent(const LoadedModel& m) {
  const ir::Mesh& mesh = m.mesh;
  const std::size_t n = mesh.positions.size();
  ASSERT_GT(mesh.triangles.size(), 0u);
  ASSERT_EQ(mesh.normals.size(), n);
  ASSERT_TRUE(mesh.uvs.empty() || mesh.uvs.size() == n);
  ASSERT_EQ(mesh.triangle_material.size(), mesh.triangles.size());
  for (const auto& t : mesh.triangles) {
    for (std::uint32_t i : t) ASSERT_LT(i, n);
  }
  for (std::int32_t mat : mesh.triangle_material) {
    ASSERT_GE(mat, 0);
    ASSERT_LT(static_cast<std::size_t>(mat), m.materials.size());
  }
  for (std::size_t i = 0; i < n; ++i) {
    ASSERT_TRUE(mesh.positions[i].allFinite());
    ASSERT_NEAR(mesh.normals[i].norm(), 1.0f, 1e-4f);
  }
  for (const ir::Material& mat : m.materials) {
    if (mat.base_color_texture >= 0) {
      ASSERT_LT(static_cast<std::size_t>(mat.base_color_texture), m.textures.size());
    }
  }
  for (const ir::Texture& tex : m.textures) {
    EXPECT_GT(tex.width, 0);
    EXPECT_GT(tex.height, 0);
    EXPECT_GE(tex.channels, 1);
    EXPECT_LE(tex.channels, 4);
    EXPECT_EQ(tex.pixels.size(), static_cast<std::size_t>(tex.width) * tex.height * tex.channels);
  }
}

void bounds(const ir::Mesh& mesh, Vector3f* lo, Vector3f* hi) {
  *lo = mesh.positions[0];
  *hi = mesh.positions[0];
  for (const Vector3f& p : mesh.positions) {
    *lo = lo->cwiseMin(p);
    *hi = hi->cwiseMax(p);
  }
}

void expect_unit_box(const ir::Mesh& mesh, float half = 0.5f) {
  Vector3f lo, hi;
  bounds(mesh, &lo, &hi);
  EXPECT_TRUE(lo.isApprox(Vector3f::Constant(-half), 1e-5f)) << lo.transpose();
  EXPECT_TRUE(hi.isApprox(Vector3f::Constant(half), 1e-5f)) << hi.transpose();
}

// For convex shapes around the origin: every normal and every triangle faces outward.
void expect_outward(const ir::Mesh& mesh, const Vector3f& centre = Vector3f::Zero()) {
  for (std::size_t i = 0; i < mesh.positions.size(); ++i) {
    EXPECT_GT(mesh.normals[i].dot(mesh.positions[i] - centre), 0) << "vertex " << i;
  }
  for (const auto& t : mesh.triangles) {
    const Vector3f& a = mesh.positions[t[0]];
    const Vector3f face = (mesh.positions[t[1]] - a).cross(mesh.positions[t[2]] - a);
    EXPECT_GT(face.dot(a - centre), 0);
  }
}

// A one-mesh glTF with a .bin beside it; `node` is the JSON of node 0 (without braces' content
// "mesh": 0, which is added).
void write_gltf(const TempDir& dir, const std::string& name, const std::vector<float>& positions,
                const std::vector<std::uint32_t>& indices, const std::string& node_extra,
                std::size_t declared_bin_length = 0) {
  std::string bin;
  for (float f : positions) append(&bin, f);
  const std::size_t index_offset = bin.size();
  for (std::uint32_t i : indices) append(&bin, i);
  const std::size_t length = declared_bin_length ? declared_bin_length : bin.size();
  const std::string json = R"({
    "asset": {"version": "2.0"},
    "scene": 0,
    "scenes": [{"nodes": [0]}],
    "nodes": [{"mesh": 0)" +
                           node_extra + R"(}],
    "meshes": [{"primitives": [{"attributes": {"POSITION": 0}, "indices": 1}]}],
    "buffers": [{"uri": ")" +
                           name + R"(.bin", "byteLength": )" + std::to_string(length) + R"(}],
    "bufferViews": [
      {"buffer": 0, "byteOffset": 0, "byteLength": )" +
                           std::to_string(index_offset) + R"(},
      {"buffer": 0, "byteOffset": )" +
                           std::to_string(index_offset) + R"(, "byteLength": )" +
                           std::to_string(length - index_offset) + R"(}],
    "accessors": [
      {"bufferView": 0, "componentType": 5126, "count": )" +
                           std::to_string(positions.size() / 3) + R"(, "type": "VEC3"},
      {"bufferView": 1, "componentType": 5125, "count": )" +
                           std::to_string(indices.size()) +
                           R"(, "type": "SCALAR"}]
  })";
  write_file(dir.file(name + ".gltf"), json);
  write_file(dir.file(name + ".bin"), bin);
}

// ---------------------------------------------------------------------------------------------
// glTF

TEST(MeshIoGltf, LoadsBoxTexturedWithTexture) {
  const LoadedModel m = load_ok(kModels + "glTF2/BoxTextured-glTF/BoxTextured.gltf");
  expect_consistent(m);
  EXPECT_EQ(m.mesh.triangles.size(), 12u);
  EXPECT_EQ(m.mesh.positions.size(), 24u);
  EXPECT_EQ(m.mesh.uvs.size(), 24u);
  expect_unit_box(m.mesh);
  expect_outward(m.mesh);
  ASSERT_EQ(m.materials.size(), 1u);
  EXPECT_EQ(m.materials[0].base_color_texture, 0);
  EXPECT_NEAR(m.materials[0].metallic, 0.0, 1e-9);
  ASSERT_EQ(m.textures.size(), 1u);
  const ir::Texture& tex = m.textures[0];
  EXPECT_EQ(tex.width, 211);
  EXPECT_EQ(tex.height, 211);
  EXPECT_NE(tex.source.find("CesiumLogoFlat.png"), std::string::npos) << tex.source;
  // The logo is not a flat colour.
  EXPECT_NE(std::count(tex.pixels.begin(), tex.pixels.end(), tex.pixels[0]),
            static_cast<std::ptrdiff_t>(tex.pixels.size()));
  for (const auto& uv : m.mesh.uvs) EXPECT_TRUE(uv.allFinite());
}

TEST(MeshIoGltf, LoadsBinaryGlbAndEmbeddedImages) {
  for (const std::string name : {"glTF2/BoxTextured-glTF-Binary/BoxTextured.glb",
                                 "glTF2/BoxTextured-glTF-Embedded/BoxTextured.gltf"}) {
    SCOPED_TRACE(name);
    const LoadedModel m = load_ok(kModels + name);
    expect_consistent(m);
    EXPECT_EQ(m.mesh.triangles.size(), 12u);
    expect_unit_box(m.mesh);
    ASSERT_EQ(m.textures.size(), 1u);
    EXPECT_EQ(m.textures[0].width, 211);
    EXPECT_NE(m.textures[0].source.find("#image0"), std::string::npos) << m.textures[0].source;
  }
}

TEST(MeshIoGltf, SpecularGlossinessDiffuseTexture) {
  const LoadedModel m =
      load_ok(kModels + "glTF2/BoxTextured-glTF-pbrSpecularGlossiness/BoxTextured.gltf");
  expect_consistent(m);
  ASSERT_EQ(m.textures.size(), 1u);
  EXPECT_EQ(m.materials[0].base_color_texture, 0);
}

TEST(MeshIoGltf, LoadsNodeHierarchy) {
  const LoadedModel m = load_ok(kModels + "glTF2/2CylinderEngine-glTF-Binary/2CylinderEngine.glb");
  expect_consistent(m);
  EXPECT_EQ(m.mesh.triangles.size(), 121496u);
  EXPECT_EQ(m.materials.size(), 34u);
}

TEST(MeshIoGltf, ComputesNormalsWhenBroken) {
  const LoadedModel m = load_ok(kModels + "glTF2/BoxBadNormals-glTF-Binary/BoxBadNormals.glb");
  expect_consistent(m);
  expect_unit_box(m.mesh);
  expect_outward(m.mesh);
}

TEST(MeshIoGltf, ConvertsYUpToZUpAndAppliesNodeTransforms) {
  TempDir dir;
  // A triangle in the glTF x-y plane, moved up by 2 (glTF +Y) and scaled by 3.
  write_gltf(dir, "tri", {0, 0, 0, 1, 0, 0, 0, 1, 0}, {0, 1, 2},
             R"(, "translation": [0, 2, 0], "scale": [3, 3, 3])");
  const LoadedModel m = load_ok(dir.file("tri.gltf"));
  expect_consistent(m);
  ASSERT_EQ(m.mesh.positions.size(), 3u);
  // (x, y, z) -> (x, -z, y)
  EXPECT_TRUE(m.mesh.positions[0].isApprox(Vector3f(0, 0, 2)));
  EXPECT_TRUE(m.mesh.positions[1].isApprox(Vector3f(3, 0, 2)));
  EXPECT_TRUE(m.mesh.positions[2].isApprox(Vector3f(0, 0, 5)));
  // Counter-clockwise seen from glTF +Z, which is RigC -Y.
  EXPECT_TRUE(m.mesh.normals[0].isApprox(Vector3f(0, -1, 0))) << m.mesh.normals[0].transpose();
  EXPECT_TRUE(m.mesh.uvs.empty());
  ASSERT_EQ(m.materials.size(), 1u);  // no material in the file: RigC's grey dielectric
  EXPECT_EQ(m.materials[0].metallic, 0.0);
  EXPECT_NEAR(m.materials[0].base_color.x(), 0.8, 1e-9);
}

TEST(MeshIoGltf, MirroringNodeKeepsWindingConsistent) {
  TempDir dir;
  write_gltf(dir, "tri", {0, 0, 0, 1, 0, 0, 0, 1, 0}, {0, 1, 2}, R"(, "scale": [-1, 1, 1])");
  const LoadedModel m = load_ok(dir.file("tri.gltf"));
  expect_consistent(m);
  const auto& t = m.mesh.triangles[0];
  const auto& p = m.mesh.positions;
  const Vector3f face = (p[t[1]] - p[t[0]]).cross(p[t[2]] - p[t[0]]);
  // Mirrored in x, the triangle still faces glTF +Z (RigC -Y).
  EXPECT_LT(face.y(), 0);
}

TEST(MeshIoGltf, RejectsMalformedFiles) {
  const std::vector<std::pair<std::string, std::string>> cases = {
      {"glTF2/IndexOutOfRange/IndexOutOfRange.gltf", "index 255 is out of range (24 vertices)"},
      {"glTF2/IndexOutOfRange/AllIndicesOutOfRange.gltf", "is out of range"},
      {"glTF2/BoxWithInfinites-glTF-Binary/BoxWithInfinites.glb", "not finite"},
      {"glTF2/MissingBin/BoxTextured.gltf", "BoxTextured0.bin"},
      {"glTF2/SchemaFailures/sceneWrongType.gltf", "scene must be"},
      {"glTF2/TestNoRootNode/NoScene.gltf", "no scene with nodes"},
      {"glTF2/TestNoRootNode/SceneWithoutNodes.gltf", "no scene with nodes"},
      {"glTF2/RecursiveNodes/RecursiveNodes.gltf", "cycle"},
      {"glTF2/IncorrectVertexArrays/Cube.gltf", "not a multiple of 3"},
      {"glTF2/draco/2CylinderEngine.gltf", "KHR_draco_mesh_compression"},
      {"glTF2/wrongTypes/badArray.gltf", "primitives must be an array"},
      {"glTF2/wrongTypes/badObject.gltf", "pbrMetallicRoughness must be an object"},
      {"glTF2/wrongTypes/badString.gltf", "name must be a string"},
      {"glTF2/wrongTypes/badUint.gltf", "index must be a non-negative integer"},
      {"glTF2/wrongTypes/badExtension.gltf", "KHR_texture_transform must be an object"},
      {"glTF2/wrongTypes/badNumber.gltf", "normalTexture"},
      {"glTF2/glTF-Asset-Generator/Mesh_PrimitiveMode/Mesh_PrimitiveMode_00.gltf",
       "contains no triangles"},
      {"glTF/BoxTextured-glTF/BoxTextured.gltf", "only glTF 2.x is supported"},
  };
  for (const auto& [name, expected] : cases) {
    ASSERT_TRUE(fs::exists(kModels + name)) << name;
    expect_load_error(kModels + name, expected);
  }
}

TEST(MeshIoGltf, RejectsAccessorsPastTheBuffer) {
  TempDir dir;
  // The buffer claims fewer bytes than the accessors need.
  write_gltf(dir, "short", {0, 0, 0, 1, 0, 0, 0, 1, 0}, {0, 1, 2}, "", 40);
  std::string error;
  EXPECT_FALSE(load_model(dir.file("short.gltf"), &error));
  EXPECT_EQ(error.rfind(dir.file("short.gltf") + ": ", 0), 0u) << error;
}

TEST(MeshIoGltf, MissingImageIsAnErrorNamingIt) {
  TempDir dir;
  const std::string src = kModels + "glTF2/BoxTextured-glTF/";
  fs::copy_file(src + "BoxTextured.gltf", dir.file("BoxTextured.gltf"));
  fs::copy_file(src + "BoxTextured0.bin", dir.file("BoxTextured0.bin"));
  expect_load_error(dir.file("BoxTextured.gltf"), "CesiumLogoFlat.png");
}

// ---------------------------------------------------------------------------------------------
// OBJ and STL (Assimp)

TEST(MeshIoObj, LoadsBox) {
  const LoadedModel m = load_ok(kModels + "OBJ/box.obj");
  expect_consistent(m);
  EXPECT_EQ(m.mesh.triangles.size(), 12u);
  EXPECT_EQ(m.mesh.positions.size(), 8u);  // identical corners are welded
  expect_unit_box(m.mesh);
  expect_outward(m.mesh);
}

TEST(MeshIoObj, LoadsSpiderWithTextures) {
  const LoadedModel m = load_ok(kModels + "OBJ/spider.obj");
  expect_consistent(m);
  EXPECT_EQ(m.mesh.triangles.size(), 1368u);
  EXPECT_EQ(m.mesh.uvs.size(), m.mesh.positions.size());
  EXPECT_EQ(m.textures.size(), 5u);
  int textured = 0;
  for (const ir::Material& mat : m.materials) textured += mat.base_color_texture >= 0;
  EXPECT_EQ(textured, 5);
  bool found = false;
  for (const ir::Texture& tex : m.textures) {
    EXPECT_FALSE(tex.pixels.empty());
    if (tex.source.find("SpiderTex.jpg") != std::string::npos) {
      found = true;
      EXPECT_EQ(tex.width, 249);
      EXPECT_EQ(tex.height, 250);
    }
  }
  EXPECT_TRUE(found);
}

TEST(MeshIoObj, MissingTextureIsAnErrorNamingIt) {
  TempDir dir;
  fs::copy_file(kModels + "OBJ/spider.obj", dir.file("spider.obj"));
  fs::copy_file(kModels + "OBJ/spider.mtl", dir.file("spider.mtl"));
  expect_load_error(dir.file("spider.obj"), "wal67ar_small.jpg");
}

// A PNG that is only its signature and header, claiming width x height RGB pixels.
std::string png_header_only(std::uint32_t width, std::uint32_t height, int bits = 8) {
  std::string png = "\x89PNG\r\n\x1a\n";
  png += std::string("\0\0\0\x0dIHDR", 8);
  for (const std::uint32_t v : {width, height}) {
    for (int shift = 24; shift >= 0; shift -= 8) png += static_cast<char>((v >> shift) & 0xFF);
  }
  png += static_cast<char>(bits);
  png += std::string("\x02\0\0\0", 4);  // RGB, deflate, no filter, no interlace
  png += std::string(4, '\0');          // the CRC (stb_image does not check it)
  return png;
}

// A texture over stb_image's 1 GB decoded says so and gives its size, instead of calling the
// file broken; a broken one still reads as broken.
TEST(MeshIoObj, ATextureTooLargeToDecodeSaysItsSize) {
  TempDir dir;
  write_file(dir.file("box.obj"),
             "mtllib box.mtl\nusemtl m\nv 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\nvt 1 0\nvt 0 1\n"
             "f 1/1 2/2 3/3\n");
  write_file(dir.file("box.mtl"), "newmtl m\nmap_Kd big.png\n");
  const std::string too_large = "more than the image decoder takes";
  write_file(dir.file("big.png"), png_header_only(20000, 20000));
  expect_load_error(dir.file("box.obj"), "big.png' is 20000 x 20000 pixels: " + too_large);
  // The header test's edge: 2^30 / 16384 / 3 = 21845 rows of RGB.
  write_file(dir.file("big.png"), png_header_only(16384, 21846));
  expect_load_error(dir.file("box.obj"), "is 16384 x 21846 pixels: " + too_large);
  // 16 bits: 16384 x 16384 as 16-bit RGBA is 2 GB.
  write_file(dir.file("big.png"), png_header_only(16384, 16384, 16));
  expect_load_error(dir.file("box.obj"), "is 16384 x 16384 pixels at 16 bits: " + too_large);
  // Under both limits (8-bit 16384 x 21845): this truncated one fails as broken.
  write_file(dir.file("big.png"), png_header_only(16384, 21845));
  expect_load_error(dir.file("box.obj"), "could not be decoded (unknown or broken image format)");
}

TEST(MeshIoObj, AMissingMaterialLibraryLoadsWithAWarning) {
  EXPECT_TRUE(load_ok(kModels + "OBJ/spider.obj").warnings.empty()) << "its spider.mtl is there";
  TempDir dir;
  write_file(dir.file("grey.obj"),
             "# a triangle\n  mtllib gone.mtl here.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n");
  write_file(dir.file("here.mtl"), "newmtl m\nKd 1 0 0\n");
  const LoadedModel m = load_ok(dir.file("grey.obj"));
  ASSERT_EQ(m.warnings.size(), 1u);
  EXPECT_EQ(m.warnings[0],
            "material library 'gone.mtl' is not beside the mesh: its colours and textures are "
            "not used");
}

TEST(MeshIoObj, RejectsFilesWithoutTriangles) {
  expect_load_error(kModels + "OBJ/testpoints.obj", "contains no triangles");
  expect_load_error(kModels + "OBJ/testline.obj", "contains no triangles");
  TempDir dir;
  write_file(dir.file("inf.obj"), "v 0 0 0\nv 1 0 0\nv inf 1 0\nf 1 2 3\n");
  std::string error;
  EXPECT_FALSE(load_model(dir.file("inf.obj"), &error));
  EXPECT_EQ(error.rfind(dir.file("inf.obj") + ": ", 0), 0u) << error;
}

TEST(MeshIoStl, AsciiAndBinaryAgreeAndAreWelded) {
  const LoadedModel a = load_ok(kModels + "STL/Spider_ascii.stl");
  const LoadedModel b = load_ok(kModels + "STL/Spider_binary.stl");
  expect_consistent(a);
  expect_consistent(b);
  EXPECT_EQ(a.mesh.triangles.size(), 1368u);
  EXPECT_EQ(b.mesh.triangles.size(), 1368u);
  EXPECT_EQ(a.mesh.positions.size(), b.mesh.positions.size());
  EXPECT_LT(a.mesh.positions.size(), 3 * a.mesh.triangles.size() / 2);  // corners shared
  Vector3f lo_a, hi_a, lo_b, hi_b;
  bounds(a.mesh, &lo_a, &hi_a);
  bounds(b.mesh, &lo_b, &hi_b);
  EXPECT_TRUE(lo_a.isApprox(lo_b, 1e-4f));
  EXPECT_TRUE(hi_a.isApprox(hi_b, 1e-4f));
}

// ---------------------------------------------------------------------------------------------
// PLY (native reader) and write_ply

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

TEST(MeshIoWritePly, ReportsFailures) {
  const ir::Mesh mesh = make_primitive(PrimitiveKind::kBox, 1, 1);
  std::string error;
  EXPECT_FALSE(write_ply("/nonexistent-dir/x/box.ply", mesh, &error));
  EXPECT_EQ(error.rfind("/nonexistent-dir/x/box.ply: ", 0), 0u) << error;
  ir::Mesh bad = mesh;
  bad.triangles.push_back({0, 1, 99});
  TempDir dir;
  EXPECT_FALSE(write_ply(dir.file("bad.ply"), bad, &error));
  EXPECT_FALSE(fs::exists(dir.file("bad.ply")));
}

// ---------------------------------------------------------------------------------------------
// General

TEST(MeshIoLoad, ReportsMissingAndUnsupportedFiles) {
  expect_load_error("/nonexistent/model.glb", "file not found");
  expect_load_error(kModels + "3DS/fels.3ds", "unsupported model format '.3ds'");
  TempDir dir;
  write_file(dir.file("garbage.glb"), "this is not a glb file at all");
  expect_load_error(dir.file("garbage.glb"), "could not be read");
  write_file(dir.file("garbage.gltf"), "{ not json");
  expect_load_error(dir.file("garbage.gltf"), "could not be read");
  write_file(dir.file("empty.stl"), "");
  expect_load_error(dir.file("empty.stl"), "");
}

}  // namespace
}  // namespace rigc
