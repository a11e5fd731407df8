// OBJ and STL through load_model (assets/assimp.cpp, textures.cpp).
#include <gtest/gtest.h>

#include <cstdint>
#include <string>

#include "assets/model_test_support.h"
#include "tests/test_support.h"

namespace rigc::model_testing {
namespace {

using ::rigc::testing::TempDir;

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

// A texture over the pixel limit (kMostTexturePixels, 8192 x 8192) says so and gives its size
// from its header, before any decoding; a broken one within it still reads as broken.
TEST(MeshIoObj, ATextureTooLargeToDecodeSaysItsSize) {
  TempDir dir;
  write_file(dir.file("box.obj"),
             "mtllib box.mtl\nusemtl m\nv 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\nvt 1 0\nvt 0 1\n"
             "f 1/1 2/2 3/3\n");
  write_file(dir.file("box.mtl"), "newmtl m\nmap_Kd big.png\n");
  const std::string too_large = "more than the 64 megapixels a texture may have";
  write_file(dir.file("big.png"), png_header_only(20000, 20000));
  expect_load_error(dir.file("box.obj"), "big.png' is 20000 x 20000 pixels: " + too_large);
  // 16000 x 16000 (775 KB as a flat PNG) took 5.2 GB to render a cube.
  write_file(dir.file("big.png"), png_header_only(16000, 16000));
  expect_load_error(dir.file("box.obj"), "is 16000 x 16000 pixels: " + too_large);
  // Past stb_image's own header test (1 GB in the file's channels): the size is still given.
  write_file(dir.file("big.png"), png_header_only(16384, 21846));
  expect_load_error(dir.file("box.obj"), "is 16384 x 21846 pixels: " + too_large);
  write_file(dir.file("big.png"), png_header_only(8193, 8192, 16));
  expect_load_error(dir.file("box.obj"), "is 8193 x 8192 pixels: " + too_large);
  // At the limit: this truncated one fails as broken.
  write_file(dir.file("big.png"), png_header_only(8192, 8192));
  expect_load_error(dir.file("box.obj"), "could not be decoded (unknown or broken image format)");
}

// A map_Kd naming a folder or a device says which, not "not found".
TEST(MeshIoObj, ATextureThatIsAFolderOrADeviceSaysSo) {
  TempDir dir;
  write_file(dir.file("box.obj"),
             "mtllib box.mtl\nusemtl m\nv 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\nvt 1 0\nvt 0 1\n"
             "f 1/1 2/2 3/3\n");
  write_file(dir.file("box.mtl"), "newmtl m\nmap_Kd tex.png\n");
  fs::create_directory(dir.file("tex.png"));
  expect_load_error(dir.file("box.obj"), "tex.png is a folder");
  fs::remove(dir.file("tex.png"));
  fs::create_symlink("/dev/zero", dir.file("tex.png"));
  expect_load_error(dir.file("box.obj"), "tex.png is not a regular file");
  fs::remove(dir.file("tex.png"));
  fs::create_symlink("tex.png", dir.file("tex.png"));
  expect_load_error(dir.file("box.obj"), "tex.png is a loop of symbolic links");
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

}  // namespace
}  // namespace rigc::model_testing
