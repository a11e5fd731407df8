#include "run/transforms_json.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <fstream>

#include "run/colmap_text.h"
#include "tests/scene_test_support.h"
#include "tests/test_support.h"

using ::testing::HasSubstr;

namespace rigc::run {
namespace {

namespace fs = std::filesystem;

TEST(BackendTransforms, CameraAndFramesInTheObjectFrame) {
  const ir::Scene scene = testing::small_scene();
  rigc::testing::TempDir dir;
  const fs::path path = dir.path() / "transforms.json";
  std::string error;
  ASSERT_TRUE(write_transforms_json(path, scene, {1, 4}, 0.25, &error)) << error;
  std::ifstream in(path);
  const nlohmann::json j = nlohmann::json::parse(in);

  EXPECT_EQ(j["camera_model"], "OPENCV");
  EXPECT_EQ(j["w"], 1368);
  EXPECT_EQ(j["h"], 912);
  EXPECT_DOUBLE_EQ(j["fl_x"].get<double>(), scene.camera.fx / 4);
  EXPECT_DOUBLE_EQ(j["fl_y"].get<double>(), scene.camera.fy / 4);
  EXPECT_DOUBLE_EQ(j["cx"].get<double>(), 684);
  EXPECT_DOUBLE_EQ(j["cy"].get<double>(), 456);
  EXPECT_EQ(j["k1"], -0.05);
  EXPECT_EQ(j["k2"], 0.01);
  EXPECT_EQ(j["p1"], 0.001);
  EXPECT_EQ(j["p2"], -0.002);

  ASSERT_EQ(j["frames"].size(), 2u);
  for (int i = 0; i < 2; ++i) {
    const nlohmann::json& frame = j["frames"][i];
    const ir::Shot& shot = scene.shots[i == 0 ? 1 : 4];
    EXPECT_EQ(frame["file_path"], "images/" + shot.name + ".jpg");
    EXPECT_EQ(frame["mask_path"], "masks/" + shot.name + ".png");
    EXPECT_EQ(frame["colmap_im_id"], shot.index + 1);
    ir::Mat4 m;
    for (int r = 0; r < 4; ++r) {
      for (int c = 0; c < 4; ++c) m(r, c) = frame["transform_matrix"][r][c].get<double>();
    }
    // Translation: the camera centre in the object frame.
    const ir::Vec3 centre = shot.object_from_camera.block<3, 1>(0, 3);
    EXPECT_LT((m.block<3, 1>(0, 3) - centre).norm(), 1e-12);
    // -Z is the viewing direction, +Y is up in the image (OpenCV's -Y), +X is right.
    const ir::Vec3 forward = shot.object_from_camera.block<3, 1>(0, 2);
    EXPECT_LT((-m.block<3, 1>(0, 2) - forward).norm(), 1e-12);
    EXPECT_LT((-m.block<3, 1>(0, 1) - shot.object_from_camera.block<3, 1>(0, 1)).norm(), 1e-12);
    EXPECT_LT((m.block<3, 1>(0, 0) - shot.object_from_camera.block<3, 1>(0, 0)).norm(), 1e-12);
    // Looking at the object: the object's middle is ahead along -Z.
    const ir::Vec3 middle = (scene.object.bounds_min_object + scene.object.bounds_max_object) / 2;
    const ir::Vec3 to_object = (middle - centre).normalized();
    EXPECT_GT(to_object.dot(-m.block<3, 1>(0, 2)), 0.99);
    EXPECT_EQ(m.row(3), Eigen::RowVector4d(0, 0, 0, 1));
  }
}

TEST(BackendTransforms, FailsOnBadShotOrMissingFolder) {
  const ir::Scene scene = testing::small_scene();
  rigc::testing::TempDir dir;
  std::string error;
  EXPECT_FALSE(write_transforms_json(dir.path() / "t.json", scene, {9}, 1, &error));
  EXPECT_THAT(error, HasSubstr("0..5"));
  EXPECT_FALSE(write_transforms_json(dir.path() / "no" / "t.json", scene, {0}, 1, &error));
  EXPECT_THAT(error, HasSubstr("t.json"));
}

}  // namespace
}  // namespace rigc::run
