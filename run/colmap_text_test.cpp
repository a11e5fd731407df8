#include "run/colmap_text.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <sstream>

#include "tests/scene_test_support.h"
#include "tests/test_support.h"

using ::testing::HasSubstr;

namespace rigc::run {
namespace {

namespace fs = std::filesystem;
using ::rigc::testing::read_text;
using ::rigc::testing::TempDir;

std::vector<std::string> lines_of(const std::string& text) {
  std::vector<std::string> lines;
  std::istringstream in(text);
  for (std::string line; std::getline(in, line);) lines.push_back(line);
  return lines;
}

TEST(BackendColmap, ImageNames) {
  EXPECT_EQ(image_extension(ir::ImageFormat::kJpeg), ".jpg");
  EXPECT_EQ(image_extension(ir::ImageFormat::kPng16), ".png");
  EXPECT_EQ(image_extension(ir::ImageFormat::kTiff16), ".tif");
  ir::Camera camera;
  ir::Shot shot;
  shot.name = "shot_007";
  camera.format = ir::ImageFormat::kTiff16;
  EXPECT_EQ(image_file_name(camera, shot), "shot_007.tif");
  EXPECT_EQ(image_relative_path(camera, shot), "images/shot_007.tif");
  EXPECT_EQ(mask_relative_path(shot), "masks/shot_007.png");
}

TEST(BackendColmap, RoundTripsPosesAndCamera) {
  const ir::Scene scene = testing::small_scene();
  ASSERT_EQ(scene.shots.size(), 6u);
  TempDir dir;
  const fs::path sparse = dir.path() / "sparse";  // created by the writer
  std::string error;
  ASSERT_TRUE(write_colmap_sparse(sparse, scene, {0, 2, 5}, 0.25, &error)) << error;

  const auto images = read_colmap_images(sparse / "images.txt", &error);
  ASSERT_TRUE(images.has_value()) << error;
  ASSERT_EQ(images->size(), 3u);
  const int expected_ids[] = {1, 3, 6};
  for (int i = 0; i < 3; ++i) {
    const ColmapImage& image = (*images)[i];
    const ir::Shot& shot = scene.shots[expected_ids[i] - 1];
    EXPECT_EQ(image.image_id, expected_ids[i]);
    EXPECT_EQ(image.camera_id, 1);
    EXPECT_EQ(image.name, shot.name + ".jpg");
    const ir::Mat4 expected = shot.object_from_camera.inverse();
    EXPECT_LT((image.camera_from_world - expected).cwiseAbs().maxCoeff(), 1e-12)
        << image.camera_from_world << "\nvs\n"
        << expected;
  }

  // Two lines per image, the second empty; quaternions with qw >= 0.
  const auto lines = lines_of(read_text((sparse / "images.txt").string()));
  ASSERT_EQ(lines.size(), 4u + 2 * 3);
  EXPECT_EQ(lines[0], "# Image list with two lines of data per image:");
  EXPECT_EQ(lines[3], "# Number of images: 3, mean observations per image: 0");
  for (int i = 0; i < 3; ++i) {
    std::istringstream fields(lines[4 + 2 * i]);
    int id = 0;
    double qw = -1;
    fields >> id >> qw;
    EXPECT_GE(qw, 0) << lines[4 + 2 * i];
    EXPECT_EQ(lines[5 + 2 * i], "");
  }

  const auto cameras = read_colmap_cameras(sparse / "cameras.txt", &error);
  ASSERT_TRUE(cameras.has_value()) << error;
  ASSERT_EQ(cameras->size(), 1u);
  const ColmapCamera& camera = cameras->front();
  EXPECT_EQ(camera.camera_id, 1);
  EXPECT_EQ(camera.model, "OPENCV");
  EXPECT_EQ(camera.width, 1368);  // 5472 / 4
  EXPECT_EQ(camera.height, 912);
  ASSERT_EQ(camera.params.size(), 8u);
  const ir::Camera& c = scene.camera;
  const std::vector<double> expected = {c.fx / 4, c.fy / 4, c.cx / 4, c.cy / 4,
                                        -0.05,    0.01,     0.001,    -0.002};
  for (int i = 0; i < 8; ++i) EXPECT_DOUBLE_EQ(camera.params[i], expected[i]) << i;
  EXPECT_EQ(camera.params[2], 684);  // image centre at w/2

  const auto points = lines_of(read_text((sparse / "points3D.txt").string()));
  ASSERT_EQ(points.size(), 3u);
  EXPECT_EQ(points[0], "# 3D point list with one line of data per point:");
}

TEST(BackendColmap, ScaledIntrinsicsFollowTheRoundedSize) {
  ir::Scene scene = testing::small_scene();
  std::string error;
  const auto camera = output_camera(scene.camera, 0.1, &error);
  ASSERT_TRUE(camera.has_value()) << error;
  EXPECT_EQ(camera->width, 547);   // 547.2
  EXPECT_EQ(camera->height, 365);  // 364.8
  EXPECT_DOUBLE_EQ(camera->fx, scene.camera.fx * 547 / 5472);
  EXPECT_DOUBLE_EQ(camera->fy, scene.camera.fy * 365 / 3648);
  EXPECT_DOUBLE_EQ(camera->cx, 547 / 2.0);
  EXPECT_DOUBLE_EQ(camera->cy, 365 / 2.0);

  EXPECT_FALSE(output_camera(scene.camera, 0, &error).has_value());
  EXPECT_THAT(error, HasSubstr("scale"));
  EXPECT_FALSE(output_camera(scene.camera, std::nan(""), &error).has_value());
}

TEST(BackendColmap, DistortionEffectOffWritesZerosAndK3UsesFullOpencv) {
  ir::Scene scene = testing::small_scene();
  scene.camera.effects.distortion = false;
  TempDir dir;
  std::string error;
  ASSERT_TRUE(write_colmap_sparse(dir.path(), scene, {0}, 0.5, &error)) << error;
  auto cameras = read_colmap_cameras(dir.path() / "cameras.txt", &error);
  ASSERT_TRUE(cameras.has_value()) << error;
  EXPECT_EQ(cameras->front().model, "OPENCV");
  ASSERT_EQ(cameras->front().params.size(), 8u);
  for (int i = 4; i < 8; ++i) EXPECT_EQ(cameras->front().params[i], 0) << i;

  scene.camera.effects.distortion = true;
  scene.camera.distortion.k3 = 0.02;
  ASSERT_TRUE(write_colmap_sparse(dir.path(), scene, {0}, 0.5, &error)) << error;
  cameras = read_colmap_cameras(dir.path() / "cameras.txt", &error);
  ASSERT_TRUE(cameras.has_value()) << error;
  EXPECT_EQ(cameras->front().model, "FULL_OPENCV");
  ASSERT_EQ(cameras->front().params.size(), 12u);
  EXPECT_EQ(cameras->front().params[8], 0.02);
}

TEST(BackendColmap, RejectsBadArguments) {
  const ir::Scene scene = testing::small_scene();
  TempDir dir;
  std::string error;
  EXPECT_FALSE(write_colmap_sparse(dir.path(), scene, {6}, 1, &error));
  EXPECT_THAT(error, HasSubstr("0..5"));
  EXPECT_FALSE(write_colmap_sparse(dir.path(), scene, {1, 1}, 1, &error));
  EXPECT_THAT(error, HasSubstr("repeated"));
  EXPECT_FALSE(write_colmap_sparse(dir.path(), scene, {0}, -1, &error));
  EXPECT_TRUE(fs::is_empty(dir.path()));
}

TEST(BackendColmap, ReadersReportMalformedLines) {
  TempDir dir;
  rigc::testing::write_text(dir.file("images.txt"), "# comment\n1 1 0 0 0 0 0 0 1\n\n");
  std::string error;
  EXPECT_FALSE(read_colmap_images(dir.path() / "images.txt", &error).has_value());
  EXPECT_THAT(error, HasSubstr("images.txt:2:"));
  rigc::testing::write_text(dir.file("cameras.txt"), "1 OPENCV 10 ten 1 2 3 4\n");
  EXPECT_FALSE(read_colmap_cameras(dir.path() / "cameras.txt", &error).has_value());
  EXPECT_THAT(error, HasSubstr("cameras.txt:1:"));
  EXPECT_FALSE(read_colmap_cameras(dir.path() / "missing.txt", &error).has_value());
}

TEST(BackendColmap, CameraLinesCOLMAPCannotUseAreErrorsAtTheirLine) {
  TempDir dir;
  const std::string good = "1 OPENCV 821 547 1146 1144 410.5 273.5 -0.02 0 0 0";
  struct Case {
    std::string line, message;
  };
  const std::vector<Case> cases = {
      {"1 OPENCV 821 547000 1146 1144 410.5 273.5 -0.02 0 0 0", "821x547000 is not an image size"},
      {"1 OPENCV 0 0 1146 1144 410.5 273.5 -0.02 0 0 0", "0x0 is not an image size"},
      {"1 OPENCV -5 547 1146 1144 410.5 273.5 -0.02 0 0 0", "-5x547 is not an image size"},
      {"1 OPENCV 821 547 nan 1144 410.5 273.5 -0.02 0 0 0", "not a finite number"},
      {"1 OPENCV 821 547 -1146 1144 410.5 273.5 -0.02 0 0 0", "focal length must be above 0"},
      {"1 SIMPLE_RADIAL 821 547 0 410.5 273.5 0", "focal length must be above 0"},
      {"1 OPENCV 821 547 1146", "OPENCV takes 8 parameters, not 1"},
      {"1 FOOCAM 821 547 1146 1144 410.5 273.5", "unknown camera model 'FOOCAM'"},
      {"1 OPENCV 821 547 1e308 1144 410.5 273.5 -0.02 0 0 0",
       "focal length 1e+308 px is more than 100 times the image's larger side (821 px)"},
      {"1 SIMPLE_PINHOLE 821 547 82101 410.5 273.5", "focal length 82101 px is more than"},
  };
  std::string error;
  for (const Case& c : cases) {
    rigc::testing::write_text(dir.file("cameras.txt"), "# header\n" + c.line + "\n");
    EXPECT_FALSE(read_colmap_cameras(dir.path() / "cameras.txt", &error).has_value()) << c.line;
    EXPECT_THAT(error, HasSubstr("cameras.txt:2: "));
    EXPECT_THAT(error, HasSubstr(c.message));
  }
  rigc::testing::write_text(dir.file("cameras.txt"), "# only comments\n");
  EXPECT_FALSE(read_colmap_cameras(dir.path() / "cameras.txt", &error).has_value());
  EXPECT_THAT(error, HasSubstr("lists no camera"));
  rigc::testing::write_text(dir.file("cameras.txt"), good + "\n2 PINHOLE 100 80 90 90 50 40\n");
  const auto cameras = read_colmap_cameras(dir.path() / "cameras.txt", &error);
  ASSERT_TRUE(cameras.has_value()) << error;
  EXPECT_EQ(cameras->size(), 2u);
}

TEST(BackendColmap, ImagesWithNonFinitePosesOrRepeatedNamesAreErrors) {
  TempDir dir;
  std::string error;
  rigc::testing::write_text(dir.file("images.txt"), "1 nan 0 0 0 0 0 0 1 a.jpg\n\n");
  EXPECT_FALSE(read_colmap_images(dir.path() / "images.txt", &error).has_value());
  EXPECT_THAT(error, HasSubstr("images.txt:1: the pose holds a number that is not finite"));
  rigc::testing::write_text(dir.file("images.txt"),
                            "1 1 0 0 0 0 0 0 1 a.jpg\n\n2 1 0 0 0 0 0 1 1 a.jpg\n\n");
  EXPECT_FALSE(read_colmap_images(dir.path() / "images.txt", &error).has_value());
  EXPECT_THAT(error, HasSubstr("images.txt:3: image 'a.jpg' is listed twice"));
}

TEST(BackendColmap, RepeatedCameraIdsAreAnError) {
  TempDir dir;
  std::string error;
  rigc::testing::write_text(dir.file("cameras.txt"),
                            "1 PINHOLE 100 80 90 90 50 40\n1 PINHOLE 100 80 91 91 50 40\n");
  EXPECT_FALSE(read_colmap_cameras(dir.path() / "cameras.txt", &error).has_value());
  EXPECT_THAT(error, HasSubstr("cameras.txt:2: camera 1 is listed twice"));
}

// A quaternion a little off unit length (few digits) is normalised; one far off is refused.
TEST(BackendColmap, NonUnitQuaternionsAreNormalisedNearOneAndRefusedFarFromIt) {
  TempDir dir;
  std::string error;
  rigc::testing::write_text(dir.file("images.txt"), "1 0.7071 0.7071 0 0 0 0 0 1 a.jpg\n\n");
  const auto images = read_colmap_images(dir.path() / "images.txt", &error);
  ASSERT_TRUE(images.has_value()) << error;
  const Eigen::Matrix3d r = (*images)[0].camera_from_world.block<3, 3>(0, 0);
  EXPECT_NEAR((r * r.transpose() - Eigen::Matrix3d::Identity()).norm(), 0, 1e-12);
  EXPECT_NEAR(r(2, 1), 1, 1e-12);  // 90 degrees about x
  for (const std::string q : {"2 0 0 0", "0.5 0 0 0", "0 0 0 0"}) {
    rigc::testing::write_text(dir.file("images.txt"), "# header\n1 " + q + " 0 0 0 1 a.jpg\n\n");
    EXPECT_FALSE(read_colmap_images(dir.path() / "images.txt", &error).has_value()) << q;
    EXPECT_THAT(error, HasSubstr("images.txt:2: the quaternion QW QX QY QZ has length"));
  }
}

TEST(BackendColmap, AnImageOfAnUndefinedCameraIsAnErrorAtItsLine) {
  TempDir dir;
  std::string error;
  rigc::testing::write_text(dir.file("cameras.txt"), "1 PINHOLE 100 80 90 90 50 40\n");
  rigc::testing::write_text(dir.file("images.txt"),
                            "# header\n1 1 0 0 0 0 0 0 1 a.jpg\n\n2 1 0 0 0 0 0 0 7 b.jpg\n\n");
  const auto cameras = read_colmap_cameras(dir.path() / "cameras.txt", &error);
  const auto images = read_colmap_images(dir.path() / "images.txt", &error);
  ASSERT_TRUE(cameras && images) << error;
  EXPECT_FALSE(check_camera_ids(*images, *cameras, dir.path() / "images.txt", &error));
  EXPECT_THAT(error,
              HasSubstr("images.txt:4: image 'b.jpg' uses camera 7, which the cameras file does "
                        "not define"));
  EXPECT_TRUE(check_camera_ids({(*images)[0]}, *cameras, dir.path() / "images.txt", &error));
}

TEST(BackendColmap, ProjectOpencvCentreAndHandComputedPoint) {
  const ir::Scene scene = testing::small_scene();
  std::string error;
  const auto camera = output_camera(scene.camera, 0.25, &error);
  ASSERT_TRUE(camera.has_value()) << error;
  for (const ir::Shot& shot : scene.shots) {
    const ir::Mat4 pose = camera_from_object(shot);
    const ir::Vec3 centre = shot.object_from_camera.block<3, 1>(0, 3);
    const ir::Vec3 forward = shot.object_from_camera.block<3, 1>(0, 2);
    const ir::Vec2 uv = project_opencv(camera->params(), pose, centre + 0.7 * forward);
    EXPECT_NEAR(uv.x(), camera->cx, 1e-9) << shot.name;
    EXPECT_NEAR(uv.y(), camera->cy, 1e-9) << shot.name;
    // The object is in view.
    const ir::Vec3 middle = (scene.object.bounds_min_object + scene.object.bounds_max_object) / 2;
    const ir::Vec2 object_uv = project_opencv(camera->params(), pose, middle);
    EXPECT_GT(object_uv.x(), 0);
    EXPECT_LT(object_uv.x(), camera->width);
    EXPECT_GT(object_uv.y(), 0);
    EXPECT_LT(object_uv.y(), camera->height);
  }

  // x = 0.1, y = -0.05, r² = 0.0125: radial = 1 - 0.05 r² + 0.01 r⁴ = 0.9993765625,
  // x' = 0.1 radial + 2(0.001)(0.1)(-0.05) - 0.002 (r² + 0.02) = 0.09986265625,
  // y' = -0.05 radial + 0.001 (r² + 0.005) + 2(-0.002)(0.1)(-0.05) = -0.049931328125.
  const std::vector<double> params = {1000, 1010, 640.5, 480.25, -0.05, 0.01, 0.001, -0.002};
  const ir::Vec3 point(0.3, -0.15, 3.0);
  ir::Vec2 uv = project_opencv(params, ir::Mat4::Identity(), point);
  EXPECT_NEAR(uv.x(), 740.36265625, 1e-9);
  EXPECT_NEAR(uv.y(), 429.81935859375, 1e-9);
  // FULL_OPENCV with k3 = 0.02 (k4..k6 = 0) adds k3 r⁶ to the radial factor.
  std::vector<double> full = params;
  full.insert(full.end(), {0.02, 0, 0, 0});
  uv = project_opencv(full, ir::Mat4::Identity(), point);
  EXPECT_NEAR(uv.x(), 740.3626601562501, 1e-9);
  EXPECT_NEAR(uv.y(), 429.81935662109373, 1e-9);
  // A translation moves the point in camera space first.
  ir::Mat4 shifted = ir::Mat4::Identity();
  shifted(2, 3) = 1.0;
  uv = project_opencv(params, shifted, ir::Vec3(0.3, -0.15, 2.0));
  EXPECT_NEAR(uv.x(), 740.36265625, 1e-9);
  // Behind the camera, or an unknown model: NaN.
  EXPECT_TRUE(std::isnan(project_opencv(params, ir::Mat4::Identity(), {0, 0, -1}).x()));
  EXPECT_TRUE(std::isnan(project_opencv({1, 2, 3}, ir::Mat4::Identity(), point).x()));
}

}  // namespace
}  // namespace rigc::run
