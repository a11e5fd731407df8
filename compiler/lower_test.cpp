// Lowering of the ways a real capture's cameras are written: poses by COLMAP's camera_from_world
// rotation, cameras by their intrinsics.
#include <fmt/format.h>
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <string>

#include "compiler/frontend.h"
#include "tests/test_support.h"

namespace rigc {
namespace {

using ::testing::HasSubstr;
using ::testing::Not;

struct Compiled {
  std::optional<ir::Scene> scene;
  std::string diagnostics;
};

Compiled compile_text(const std::string& text) {
  DiagnosticEngine diag;
  Compiled result;
  rigc::testing::capture_diagnostics(diag, result.diagnostics);
  result.scene = compile_scene_text(text, "test.yaml", ".", diag);
  return result;
}

// A sphere on the turntable, a body or `camera` lines, and `shots` (YAML list entries).
std::string scene_text(const std::string& shots, const std::string& camera =
                                                     "  body: canon-6d\n"
                                                     "  lens: {focal_length: 50mm}\n") {
  return "rigc: 1\n"
         "object:\n"
         "  primitive: sphere\n"
         "  fit: {height: 20cm}\n"
         "  surface: {pattern: speckle}\n"
         "camera:\n" +
         camera +
         "  exposure: {aperture: f/8, shutter: 1/125, iso: 200}\n"
         "shots:\n" +
         shots;
}

// A camera_from_world rotation that is no axis permutation: yaw, pitch and roll all non-zero.
Eigen::Matrix3d some_camera_from_world() {
  const Eigen::Matrix3d world_from_camera =
      (Eigen::AngleAxisd(0.3, ir::Vec3::UnitZ()) * Eigen::AngleAxisd(-1.7, ir::Vec3::UnitX()) *
       Eigen::AngleAxisd(0.05, ir::Vec3::UnitZ()))
          .toRotationMatrix();
  return world_from_camera.transpose();
}

// [[r11, r12, r13], ...] to the last digit.
std::string matrix_text(const Eigen::Matrix3d& r) {
  return fmt::format("[[{}, {}, {}], [{}, {}, {}], [{}, {}, {}]]", r(0, 0), r(0, 1), r(0, 2),
                     r(1, 0), r(1, 1), r(1, 2), r(2, 0), r(2, 1), r(2, 2));
}

std::string rotation_pose(const ir::Vec3& c, const std::string& rotation,
                          const std::string& extra = "") {
  return fmt::format("  - pose: {{position: [{}, {}, {}], rotation: {}{}}}\n", c.x(), c.y(), c.z(),
                     rotation, extra);
}

// COLMAP's camera_from_world [R | t] of a shot's world_from_camera.
ir::Mat4 camera_from_world(const ir::Shot& shot) {
  return shot.world_from_camera.inverse();
}

TEST(LowerPose, RotationPoseLowersToExactlyTheGivenCameraFromWorld) {
  const Eigen::Matrix3d r = some_camera_from_world();
  const ir::Vec3 c(0.31, -0.62, 1.07);
  const Compiled compiled = compile_text(scene_text(rotation_pose(c, matrix_text(r))));
  ASSERT_TRUE(compiled.scene) << compiled.diagnostics;
  ASSERT_EQ(compiled.scene->shots.size(), 1u);
  const ir::Mat4 pose = camera_from_world(compiled.scene->shots[0]);
  EXPECT_LT((pose.topLeftCorner<3, 3>() - r).cwiseAbs().maxCoeff(), 1e-9);
  EXPECT_LT((pose.topRightCorner<3, 1>() - (-r * c)).cwiseAbs().maxCoeff(), 1e-9);
  EXPECT_LT((compiled.scene->shots[0].world_from_camera.topRightCorner<3, 1>() - c).norm(), 1e-12);
}

// COLMAP's images.txt order: qw qx qy qz.
TEST(LowerPose, QuaternionGivesTheSameCameraFromWorldAsItsMatrix) {
  const Eigen::Matrix3d r = some_camera_from_world();
  const Eigen::Quaterniond q(r);
  const ir::Vec3 c(0.31, -0.62, 1.07);
  const std::string quaternion =
      fmt::format("{{quaternion: [{}, {}, {}, {}]}}", q.w(), q.x(), q.y(), q.z());
  const Compiled compiled = compile_text(scene_text(rotation_pose(c, quaternion)));
  ASSERT_TRUE(compiled.scene) << compiled.diagnostics;
  const ir::Mat4 pose = camera_from_world(compiled.scene->shots[0]);
  EXPECT_LT((pose.topLeftCorner<3, 3>() - r).cwiseAbs().maxCoeff(), 1e-9);
}

// The rotation of a look_at pose, written out, is the same shot: the same poses in the world and
// in the object frame (the turntable turns the object under the camera in both), the same focus.
TEST(LowerPose, LookAtPoseAndItsRotationGiveTheSameIr) {
  const std::string look_at =
      "  - pose: {position: [0.4m, -0.7m, 1.1m], look_at: [0.02m, 0, 0.86m], turntable: 35deg}\n";
  const Compiled by_look_at = compile_text(scene_text(look_at));
  ASSERT_TRUE(by_look_at.scene) << by_look_at.diagnostics;
  const ir::Shot& a = by_look_at.scene->shots.at(0);
  const Eigen::Matrix3d r = a.world_from_camera.topLeftCorner<3, 3>().transpose();
  const Compiled by_rotation = compile_text(scene_text(rotation_pose(
      a.world_from_camera.topRightCorner<3, 1>(), matrix_text(r), ", turntable: 35deg")));
  ASSERT_TRUE(by_rotation.scene) << by_rotation.diagnostics;
  const ir::Shot& b = by_rotation.scene->shots.at(0);
  EXPECT_LT((a.world_from_camera - b.world_from_camera).cwiseAbs().maxCoeff(), 1e-9);
  EXPECT_LT((a.object_from_camera - b.object_from_camera).cwiseAbs().maxCoeff(), 1e-9);
  EXPECT_DOUBLE_EQ(a.turntable_angle_rad, b.turntable_angle_rad);
  EXPECT_EQ(a.kind, b.kind);
  // look_at focuses on its point, a rotation on the object's centre: 2 cm apart across the view.
  EXPECT_NEAR(a.focus_distance_m, b.focus_distance_m, 0.02);
}

// Rotations written to six digits are within the tolerance and come out orthonormal.
TEST(LowerPose, NearlyOrthonormalRotationIsReorthonormalised) {
  Eigen::Matrix3d r = some_camera_from_world();
  r(0, 1) += 1e-6;
  r(2, 0) -= 2e-6;
  const Compiled compiled =
      compile_text(scene_text(rotation_pose({0.31, -0.62, 1.07}, matrix_text(r))));
  ASSERT_TRUE(compiled.scene) << compiled.diagnostics;
  const Eigen::Matrix3d lowered = camera_from_world(compiled.scene->shots[0]).topLeftCorner<3, 3>();
  EXPECT_LT((lowered.transpose() * lowered - Eigen::Matrix3d::Identity()).cwiseAbs().maxCoeff(),
            1e-12);
  EXPECT_NEAR(lowered.determinant(), 1, 1e-12);
  EXPECT_LT((lowered - r).cwiseAbs().maxCoeff(), 3e-6);
}

std::string intrinsics_camera(const std::string& extra_intrinsics, const std::string& lens = "") {
  return "  intrinsics: {width: 640, height: 480, fx: 1520.4, fy: 1525.9, cx: 302.3, cy: 246.9" +
         extra_intrinsics + "}\n" + lens;
}

const char* kOnePose = "  - pose: {position: [0, -1m, 0.85m], look_at: object}\n";

TEST(LowerIntrinsics, GivenIntrinsicsReachTheIrAsGiven) {
  const Compiled compiled = compile_text(scene_text(kOnePose, intrinsics_camera("")));
  ASSERT_TRUE(compiled.scene) << compiled.diagnostics;
  EXPECT_THAT(compiled.diagnostics, Not(HasSubstr("not square"))) << "fx != fy is measured";
  const ir::Camera& camera = compiled.scene->camera;
  EXPECT_EQ(camera.width_px, 640);
  EXPECT_EQ(camera.height_px, 480);
  EXPECT_EQ(camera.fx, 1520.4);
  EXPECT_EQ(camera.fy, 1525.9);
  EXPECT_EQ(camera.cx, 302.3);
  EXPECT_EQ(camera.cy, 246.9);
  // The default pixel pitch, 5 um: the focal length fx · pitch, the sensor the image's size.
  EXPECT_NEAR(camera.focal_length_m, 1520.4 * 5e-6, 1e-15);
  EXPECT_NEAR(camera.sensor_width_m, 640 * 5e-6, 1e-15);
  EXPECT_NEAR(camera.focal_length_m * camera.height_px / camera.sensor_height_m, 1525.9, 1e-9)
      << "the sensor's height is the one fy gives";
  EXPECT_EQ(camera.body, "custom");
}

TEST(LowerIntrinsics, PixelPitchOrFocalLengthSizesTheSensor) {
  const Compiled pitch =
      compile_text(scene_text(kOnePose, intrinsics_camera(", pixel_pitch: 3.76um")));
  ASSERT_TRUE(pitch.scene) << pitch.diagnostics;
  EXPECT_NEAR(pitch.scene->camera.focal_length_m, 1520.4 * 3.76e-6, 1e-15);
  EXPECT_NEAR(pitch.scene->camera.sensor_width_m, 640 * 3.76e-6, 1e-15);

  const Compiled focal = compile_text(scene_text(
      kOnePose, intrinsics_camera("", "  lens: {focal_length: 6mm, vignetting: 0.1}\n")));
  ASSERT_TRUE(focal.scene) << focal.diagnostics;
  EXPECT_DOUBLE_EQ(focal.scene->camera.focal_length_m, 0.006);
  EXPECT_NEAR(focal.scene->camera.sensor_width_m, 640 * 0.006 / 1520.4, 1e-15);
  EXPECT_EQ(focal.scene->camera.fx, 1520.4) << "the focal length does not recompute fx";

  // A focal length that agrees with fx · pitch (to 1 %) is no conflict.
  const Compiled both = compile_text(scene_text(
      kOnePose, intrinsics_camera(", pixel_pitch: 5um", "  lens: {focal_length: 7.6mm}\n")));
  EXPECT_TRUE(both.scene) << both.diagnostics;
}

TEST(LowerIntrinsics, DistortionIsCheckedOverTheFartherEdge) {
  // k1 = -0.1 folds the image over 1.83 focal lengths from the principal point, where it has
  // moved points 1.22 out: beyond a centred 640 x 480 frame's corner at fx = 400 (1.0 out), short
  // of the right edge of one whose principal point is 40 px from the left (1.5 out).
  const auto camera = [](int cx) {
    return fmt::format(
        "  intrinsics: {{width: 640, height: 480, fx: 400, fy: 400, cx: {}, cy: 240}}\n"
        "  lens: {{distortion: {{k1: -0.1}}}}\n",
        cx);
  };
  const Compiled centred = compile_text(scene_text(kOnePose, camera(320)));
  EXPECT_TRUE(centred.scene) << centred.diagnostics;
  const Compiled off_centre = compile_text(scene_text(kOnePose, camera(40)));
  EXPECT_FALSE(off_centre.scene);
  EXPECT_THAT(off_centre.diagnostics, HasSubstr("folds the image over"));
}

}  // namespace
}  // namespace rigc
