#include "eval/pose_accuracy.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>

#include "eval/align.h"

namespace rigc::eval {
namespace {

// camera_from_world of a camera at `eye` looking at `target`, +Z up in the world.
Mat4 looking_at(const Vec3& eye, const Vec3& target) {
  const Vec3 forward = (target - eye).normalized();
  const Vec3 right = forward.cross(Vec3::UnitZ()).normalized();
  const Vec3 down = forward.cross(right);
  Mat4 m = Mat4::Identity();
  m.topLeftCorner<3, 3>().row(0) = right.transpose();
  m.topLeftCorner<3, 3>().row(1) = down.transpose();
  m.topLeftCorner<3, 3>().row(2) = forward.transpose();
  m.topRightCorner<3, 1>() = -m.topLeftCorner<3, 3>() * eye;
  return m;
}

// A ring of `n` cameras 0.6 m from (0.1, 0.2, 0.05), 0.2 m above it.
struct Ring {
  std::vector<std::string> names;
  KnownCameras reference;
};
Ring make_ring(int n) {
  Ring r;
  const Vec3 object(0.1, 0.2, 0.05);
  for (int i = 0; i < n; ++i) {
    const double a = 2 * M_PI * i / n;
    const Vec3 eye = object + Vec3(0.6 * std::cos(a), 0.6 * std::sin(a), 0.2);
    r.names.push_back("view" + std::to_string(i) + ".png");
    r.reference[r.names.back()].camera_from_world = looking_at(eye, object);
  }
  return r;
}

// The same cameras in a frame x' = s R x + t, as SfM reports them (its own gauge).
std::map<std::string, Mat4> in_another_frame(const KnownCameras& cameras, const Similarity& s) {
  std::map<std::string, Mat4> out;
  const Similarity inverse = s.inverse();
  for (const auto& [name, cam] : cameras) {
    // A camera_from_world pose P becomes P * S^-1, with the scale moved into the translation.
    const Eigen::Matrix3d r = cam.camera_from_world.topLeftCorner<3, 3>() * inverse.rotation;
    Mat4 m = Mat4::Identity();
    m.topLeftCorner<3, 3>() = r;
    m.topRightCorner<3, 1>() = -r * s.apply(camera_centre(cam.camera_from_world));
    out[name] = m;
  }
  return out;
}

Similarity some_similarity() {
  Similarity s;
  s.scale = 3.7;
  s.rotation = Eigen::AngleAxisd(0.7, Vec3(1, 2, 3).normalized()).toRotationMatrix();
  s.translation = Vec3(-2, 5, 1);
  return s;
}

TEST(PoseAccuracy, AucIsTheTrapezoidAreaUnderTheRecallCurve) {
  // Recall 1/2 at 1 deg, 1 at 3 deg: up to 2 deg the area is 0.25 + 0.5 of 2; up to 10 deg
  // 0.25 + 1.5 + 7 of 10.
  EXPECT_THAT(pose_auc({3, 1}, {2, 10}),
              ::testing::ElementsAre(::testing::DoubleNear(37.5, 1e-12),
                                     ::testing::DoubleNear(87.5, 1e-12)));
  EXPECT_THAT(pose_auc({0, 0, 0}, {1}), ::testing::ElementsAre(::testing::DoubleNear(100, 1e-12)));
  EXPECT_THAT(pose_auc({180}, {1, 10}), ::testing::ElementsAre(0.0, 0.0));
}

TEST(PoseAccuracy, TheSameCamerasInAnotherFrameHaveNoError) {
  const Ring ring = make_ring(16);
  const auto estimated = in_another_frame(ring.reference, some_similarity());
  const PoseAccuracy acc = measure_pose_accuracy(ring.names, ring.reference, estimated, {});
  ASSERT_TRUE(acc.ok) << acc.failure;
  EXPECT_NEAR(acc.reference_from_reconstruction.scale, 1 / 3.7, 1e-9);
  EXPECT_NEAR((acc.object_centre - Vec3(0.1, 0.2, 0.05)).norm(), 0, 1e-9);
  for (const auto& p : acc.photos) {
    EXPECT_TRUE(p.registered);
    EXPECT_NEAR(p.rotation_deg, 0, 1e-6) << p.name;
    EXPECT_NEAR(p.centre_m, 0, 1e-9) << p.name;
  }
  // Rounding leaves errors of 1e-7 degrees: the curve reaches 1 a hair after 0.
  for (double auc : acc.auc) EXPECT_NEAR(auc, 100, 1e-3);
}

TEST(PoseAccuracy, ARotatedCameraAndALostOneShowWhereTheyShould) {
  const Ring ring = make_ring(16);
  auto estimated = in_another_frame(ring.reference, some_similarity());
  estimated.erase("view3.png");
  // view5 turned 2 degrees about its optical axis, and moved 6 mm (in the reference) sideways.
  Mat4& turned = estimated.at("view5.png");
  const Eigen::Matrix3d roll = Eigen::AngleAxisd(2 * M_PI / 180, Vec3::UnitZ()).toRotationMatrix();
  const Vec3 centre = camera_centre(turned);
  turned.topLeftCorner<3, 3>() = roll * turned.topLeftCorner<3, 3>();
  const Vec3 right = turned.topLeftCorner<3, 3>().row(0).transpose();
  turned.topRightCorner<3, 1>() = -turned.topLeftCorner<3, 3>() * (centre + 3.7 * 0.006 * right);
  const PoseAccuracy acc = measure_pose_accuracy(ring.names, ring.reference, estimated, {});
  ASSERT_TRUE(acc.ok) << acc.failure;
  EXPECT_FALSE(acc.photos[3].registered);
  // The least-squares fit shares view5's 6 mm among the 15 centres a little.
  EXPECT_NEAR(acc.photos[5].rotation_deg, 2, 0.05);
  EXPECT_NEAR(acc.photos[5].centre_m, 0.006, 0.0015);
  EXPECT_NEAR(acc.photos[5].centre_percent, 100 * acc.photos[5].centre_m / std::hypot(0.6, 0.2),
              1e-6);
  EXPECT_NEAR(acc.photos[4].rotation_deg, 0, 0.05);
  // 30 of the 240 ordered pairs have the lost photo (180 deg); 28 more have view5 (about 2 deg).
  EXPECT_NEAR(acc.auc[0], 100.0 * (240 - 30 - 28) / 240, 1e-3);
  EXPECT_LT(acc.auc[3], 100.0 * (240 - 30) / 240);
  EXPECT_GT(acc.auc[3], 100.0 * (240 - 30 - 28) / 240);
  EXPECT_EQ(acc.report["registered"], 15);
}

TEST(PoseAccuracy, FocalLengthErrorIsAgainstTheReferenceIntrinsics) {
  const Ring ring = make_ring(8);
  KnownCameras reference = ring.reference;
  for (auto& [name, cam] : reference) {
    cam.intrinsics = run::ColmapCamera{1, "PINHOLE", 640, 480, {1520, 1525, 320, 240}};
  }
  const auto estimated = in_another_frame(reference, some_similarity());
  std::map<std::string, run::ColmapCamera> intrinsics;
  // COLMAP ran on the photos at half size with a focal length 1 % long.
  for (const auto& name : ring.names) {
    intrinsics[name] = run::ColmapCamera{1, "SIMPLE_RADIAL", 320, 240, {768, 160, 120, 0}};
  }
  const PoseAccuracy acc = measure_pose_accuracy(ring.names, reference, estimated, intrinsics);
  ASSERT_TRUE(acc.ok) << acc.failure;
  EXPECT_NEAR(acc.photos[0].focal_percent, 100 * (1536.0 - 1520) / 1520, 1e-9);
}

TEST(PoseAccuracy, TooFewRegisteredPhotosCannotBeFitted) {
  const Ring ring = make_ring(8);
  auto estimated = in_another_frame(ring.reference, some_similarity());
  for (int i = 2; i < 8; ++i) estimated.erase("view" + std::to_string(i) + ".png");
  const PoseAccuracy acc = measure_pose_accuracy(ring.names, ring.reference, estimated, {});
  EXPECT_FALSE(acc.ok);
  EXPECT_THAT(acc.failure, ::testing::HasSubstr("2 registered photos"));
}

TEST(PoseAccuracy, ParallelAxesHaveNoNearestPoint) {
  Mat4 a = Mat4::Identity(), b = Mat4::Identity();
  b(0, 3) = 1;
  EXPECT_FALSE(point_nearest_axes({a, b}).has_value());
}

}  // namespace
}  // namespace rigc::eval
