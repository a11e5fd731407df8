// glTF through load_model (assets/gltf.cpp, gltf_schema.cpp).
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cstdint>
#include <string>
#include <vector>

#include "assets/model_test_support.h"
#include "tests/test_support.h"

using ::testing::HasSubstr;

namespace rigc::model_testing {
namespace {

using ::rigc::testing::TempDir;

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
  EXPECT_THAT(tex.source, HasSubstr("CesiumLogoFlat.png"));
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
    EXPECT_THAT(m.textures[0].source, HasSubstr("#image0"));
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

TEST(MeshIoGltf, ErrorCutsALongDataUri) {
  TempDir dir;
  // tinygltf's message for a data URI that disagrees with its byteLength holds the whole URI.
  const std::string uri = "data:application/octet-stream;base64," + std::string(400'000, 'A');
  write_file(dir.file("uri.gltf"), R"({"asset": {"version": "2.0"}, "buffers": [{"uri": ")" + uri +
                                       R"(", "byteLength": 7}]})");
  std::string error;
  EXPECT_FALSE(load_model(dir.file("uri.gltf"), &error));
  EXPECT_LT(error.size(), 600u) << error.substr(0, 600);
  EXPECT_THAT(error, HasSubstr("data:application/octet-stream;base64,AAAA"));
  EXPECT_THAT(error, HasSubstr("... (400037 characters)"));
}

TEST(MeshIoGltf, ImageThatIsAFolderOrADeviceSaysSo) {
  TempDir dir;
  const std::string src = kModels + "glTF2/BoxTextured-glTF/";
  std::string gltf = ::rigc::testing::read_text(src + "BoxTextured.gltf");
  fs::copy_file(src + "BoxTextured0.bin", dir.file("BoxTextured0.bin"));
  fs::create_directory(dir.file("CesiumLogoFlat.png"));
  write_file(dir.file("BoxTextured.gltf"), gltf);
  expect_load_error(dir.file("BoxTextured.gltf"), "image 0 'CesiumLogoFlat.png' is a folder");
  fs::create_symlink("/dev/zero", dir.file("zero.png"));
  const std::size_t at = gltf.find("CesiumLogoFlat.png");
  ASSERT_NE(at, std::string::npos);
  write_file(dir.file("BoxTextured.gltf"), gltf.replace(at, 18, "zero.png"));
  expect_load_error(dir.file("BoxTextured.gltf"), "image 0 'zero.png' is not a regular file");
}

TEST(MeshIoGltf, MissingImageIsAnErrorNamingIt) {
  TempDir dir;
  const std::string src = kModels + "glTF2/BoxTextured-glTF/";
  fs::copy_file(src + "BoxTextured.gltf", dir.file("BoxTextured.gltf"));
  fs::copy_file(src + "BoxTextured0.bin", dir.file("BoxTextured0.bin"));
  expect_load_error(dir.file("BoxTextured.gltf"), "CesiumLogoFlat.png");
}

}  // namespace
}  // namespace rigc::model_testing
