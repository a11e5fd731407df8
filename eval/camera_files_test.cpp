#include "eval/camera_files.h"

#include <fmt/format.h>
#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <sys/stat.h>

#include <cstdlib>
#include <nlohmann/json.hpp>

#include "eval/reconstruction_test_support.h"

using ::testing::HasSubstr;

namespace rigc::eval {
namespace {

using nlohmann::json;

// A Meshroom SfMData of the statue run's poses, as AliceVision writes it: numbers as strings, the
// world-to-camera rotation column by column, the centre; one view without a pose.
json meshroom_sfm(const test_inputs::StatueRun& r) {
  json views = json::array(), poses = json::array();
  for (int index : r.shots) {
    const ir::Shot& shot = r.scene.shots[index];
    const ir::Mat4 pose = run::camera_from_object(shot);
    const std::string id = std::to_string(1000 + index);
    views.push_back({{"viewId", id},
                     {"poseId", id},
                     {"path", "/data/photos/" + run::image_file_name(r.scene.camera, shot)}});
    json rotation = json::array(), centre = json::array();
    for (int k = 0; k < 9; ++k) rotation.push_back(fmt::format("{:.17g}", pose(k % 3, k / 3)));
    const ir::Vec3 c = shot.object_from_camera.topRightCorner<3, 1>();
    for (int k = 0; k < 3; ++k) centre.push_back(fmt::format("{:.17g}", c(k)));
    poses.push_back(
        {{"poseId", id}, {"pose", {{"transform", {{"rotation", rotation}, {"center", centre}}}}}});
  }
  views.push_back({{"viewId", "7"}, {"poseId", "7"}, {"path", "/data/photos/lost.jpg"}});
  return {{"version", {"1", "2", "0"}}, {"views", views}, {"poses", poses}};
}

TEST(CameraFiles, MeshroomSfmGivesThePoses) {
  rigc::testing::TempDir dir;
  const auto r = test_inputs::make_statue_run(dir.path(), 100);
  ASSERT_TRUE(r);
  rigc::testing::write_text(dir.file("cameras.sfm"), meshroom_sfm(*r).dump(2));
  std::string error;
  const auto file = read_camera_file(dir.file("cameras.sfm"), &error);
  ASSERT_TRUE(file) << error;
  EXPECT_EQ(file->format, "Meshroom SfMData");
  ASSERT_EQ(file->images.size(), r->shots.size());  // the view without a pose is left out
  for (std::size_t i = 0; i < r->shots.size(); ++i) {
    const ir::Shot& shot = r->scene.shots[r->shots[i]];
    EXPECT_EQ(file->images[i].name, run::image_file_name(r->scene.camera, shot));
    EXPECT_LT((file->images[i].camera_from_world - run::camera_from_object(shot)).norm(), 1e-9);
  }
}

TEST(CameraFiles, BrokenFilesAreNamed) {
  rigc::testing::TempDir dir;
  std::string error;
  rigc::testing::write_text(dir.file("a.sfm"), "{\"views\": []}");
  EXPECT_FALSE(read_camera_file(dir.file("a.sfm"), &error));
  EXPECT_THAT(error, HasSubstr("a.sfm: is not a Meshroom SfMData"));
  rigc::testing::write_text(dir.file("b.out"), "# Bundle file v0.3\n1 0\n");
  EXPECT_FALSE(read_camera_file(dir.file("b.out"), &error));
  EXPECT_THAT(error, HasSubstr("no image list"));
  rigc::testing::write_text(dir.file("b.list.txt"), "x.jpg\n");
  EXPECT_FALSE(read_camera_file(dir.file("b.out"), &error));
  EXPECT_THAT(error, HasSubstr("camera 0 is incomplete"));
  rigc::testing::write_text(dir.file("images.bin"), "xx");
  rigc::testing::write_text(dir.file("cameras.bin"), "xx");
  EXPECT_FALSE(read_camera_file(dir.path(), &error));
  EXPECT_THAT(error, HasSubstr("ends early"));
  EXPECT_FALSE(read_camera_file(dir.file("c.xyz"), &error));
  EXPECT_THAT(error, HasSubstr("does not exist"));
}

// Neither read forever nor waited on: /dev/zero behind a Bundler .out (it read 4.4 GB), a pipe
// named *.sfm (it blocked for ever), a folder whose images.txt is a pipe.
TEST(CameraFiles, DevicesAndPipesAreRefusedUnread) {
  rigc::testing::TempDir dir;
  std::string error;
  std::filesystem::create_symlink("/dev/zero", dir.file("zero.out"));
  rigc::testing::write_text(dir.file("zero.list.txt"), "x.jpg\n");
  EXPECT_FALSE(read_camera_file(dir.file("zero.out"), &error));
  EXPECT_THAT(error, ::testing::HasSubstr("zero.out: cannot read it: it is not a regular file"));
  ASSERT_EQ(::mkfifo(dir.file("pipe.sfm").c_str(), 0600), 0);
  EXPECT_FALSE(read_camera_file(dir.file("pipe.sfm"), &error));
  EXPECT_THAT(error, ::testing::HasSubstr("is not a regular file"));
  std::filesystem::create_directory(dir.file("model"));
  ASSERT_EQ(::mkfifo(dir.file("model/images.txt").c_str(), 0600), 0);
  EXPECT_FALSE(read_camera_file(dir.file("model"), &error));
  EXPECT_THAT(error, ::testing::HasSubstr("is not a regular file"));
}

TEST(CameraFiles, RigcCameraCsvGivesTheRunsPoses) {
  rigc::testing::TempDir dir;
  const auto r = test_inputs::make_statue_run(dir.path(), 100);
  ASSERT_TRUE(r);
  std::string error;
  const auto file = read_camera_file(r->dir / "cameras.csv", &error);
  ASSERT_TRUE(file) << error;
  EXPECT_EQ(file->format, "RigC cameras.csv");
  ASSERT_EQ(file->images.size(), r->shots.size());
  for (std::size_t i = 0; i < r->shots.size(); ++i) {
    const ir::Shot& shot = r->scene.shots[r->shots[i]];
    EXPECT_EQ(file->images[i].name, run::image_file_name(r->scene.camera, shot));
    // The file holds nine significant digits.
    EXPECT_LT((file->images[i].camera_from_world - run::camera_from_object(shot)).norm(), 1e-6);
  }
}

// The real temple's calibration (tests/real/README.md): every camera sees the object's bounding
// box centre inside its 640 x 480 photo, in front of it.
TEST(CameraFiles, MiddleburyParFileGivesPosesAndIntrinsics) {
  std::string error;
  const auto file = read_camera_file(
      std::string(RIGC_SOURCE_DIR) + "/tests/real/templeSparseRing/templeSR_par.txt", &error);
  ASSERT_TRUE(file) << error;
  EXPECT_EQ(file->format, "Middlebury");
  ASSERT_EQ(file->images.size(), 16u);
  ASSERT_EQ(file->cameras.size(), 16u);
  EXPECT_EQ(file->images[0].name, "templeSR0001.png");
  EXPECT_EQ(file->cameras[0].model, "PINHOLE");
  EXPECT_THAT(file->cameras[0].params, ::testing::ElementsAre(1520.4, 1525.9, 302.32, 246.87));
  const ir::Vec3 centre =
      (ir::Vec3(-0.073568, 0.021728, -0.012445) + ir::Vec3(0.028855, 0.181892, 0.062736)) / 2;
  const KnownCameras known = known_cameras(*file);
  ASSERT_EQ(known.size(), 16u);
  for (const auto& [name, camera] : known) {
    const ir::Vec3 x = camera.camera_from_world.topLeftCorner<3, 3>() * centre +
                       camera.camera_from_world.topRightCorner<3, 1>();
    ASSERT_GT(x.z(), 0.3) << name;
    const auto& k = camera.intrinsics->params;
    const double u = k[0] * x.x() / x.z() + k[2], v = k[1] * x.y() / x.z() + k[3];
    EXPECT_GT(u, 200) << name;
    EXPECT_LT(u, 440) << name;
    EXPECT_GT(v, 120) << name;
    EXPECT_LT(v, 360) << name;
  }
}

TEST(CameraFiles, BrokenParAndCsvFilesAreNamedWithTheirLine) {
  rigc::testing::TempDir dir;
  std::string error;
  const std::string k = "1500 0 320 0 1500 240 0 0 1";
  rigc::testing::write_text(dir.file("a_par.txt"), "2\nx.png " + k + " 1 0 0 0 1 0 0 0 1 0 0 1\n");
  EXPECT_FALSE(read_camera_file(dir.file("a_par.txt"), &error));
  EXPECT_THAT(error, ::testing::HasSubstr("says 2 images but has 1 lines"));
  rigc::testing::write_text(dir.file("b_par.txt"), "1\nx.png " + k + " 1 0 0 0 1 0 0 0 2 0 0 1\n");
  EXPECT_FALSE(read_camera_file(dir.file("b_par.txt"), &error));
  EXPECT_THAT(error, ::testing::HasSubstr("b_par.txt: line 2: R is not a rotation"));
  rigc::testing::write_text(dir.file("c_par.txt"), "1\nx.png " + k + " 1 0 0 0 1 0\n");
  EXPECT_FALSE(read_camera_file(dir.file("c_par.txt"), &error));
  EXPECT_THAT(error, ::testing::HasSubstr("line 2: expected an image name and 21 numbers"));
  rigc::testing::write_text(dir.file("d.csv"), "label,x,y,z,omega,phi,kappa\nx.jpg,1,2,3,4,5\n");
  EXPECT_FALSE(read_camera_file(dir.file("d.csv"), &error));
  EXPECT_THAT(error, ::testing::HasSubstr("d.csv: line 2: expected a name and six numbers"));
  rigc::testing::write_text(dir.file("e.csv"), "name,a,b\n");
  EXPECT_FALSE(read_camera_file(dir.file("e.csv"), &error));
  EXPECT_THAT(error, ::testing::HasSubstr("not RigC's cameras.csv"));
}

// COLMAP's binary model (written by COLMAP itself from the text one) reads as the text one.
TEST(CameraFiles, ColmapBinaryModelReadsAsTheTextOne) {
  RIGC_REQUIRE_TOOL(std::system("colmap -h > /dev/null 2>&1") == 0, "colmap");
  rigc::testing::TempDir dir;
  const auto r = test_inputs::make_statue_run(dir.path(), 500);
  ASSERT_TRUE(r);
  std::filesystem::create_directories(dir.path() / "bin");
  const auto result = rigc::testing::run_process({"colmap", "model_converter", "--input_path",
                                                  (r->dir / "sparse").string(), "--output_path",
                                                  dir.file("bin"), "--output_type", "BIN"});
  ASSERT_EQ(result.exit_code, 0) << result.out << result.err;
  std::string error;
  const auto text = read_camera_file(r->dir / "sparse", &error);
  ASSERT_TRUE(text) << error;
  const auto binary = read_camera_file(dir.path() / "bin" / "images.bin", &error);
  ASSERT_TRUE(binary) << error;
  EXPECT_EQ(binary->format, "COLMAP binary");
  ASSERT_EQ(binary->cameras.size(), 1u);
  EXPECT_EQ(binary->cameras[0].model, text->cameras[0].model);
  EXPECT_EQ(binary->cameras[0].params, text->cameras[0].params);
  ASSERT_EQ(binary->images.size(), text->images.size());
  std::map<std::string, ir::Mat4> by_name;
  for (const auto& im : text->images) by_name[im.name] = im.camera_from_world;
  for (const auto& im : binary->images) {
    ASSERT_TRUE(by_name.count(im.name)) << im.name;
    EXPECT_LT((im.camera_from_world - by_name[im.name]).norm(), 1e-12);
  }
}

}  // namespace
}  // namespace rigc::eval
