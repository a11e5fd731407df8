// Registration without poses: photos taken as the scene plans register from its camera ring
// whatever turn of the turntable they started at (the statue fixture's plan: two rings of six).
#include "eval/align.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>
#include <string>

#include "compiler/frontend.h"
#include "eval/inputs.h"
#include "eval/reconstruction_test_support.h"
#include "ir/ir.h"
#include "tests/test_support.h"

namespace rigc::eval {
namespace {

struct RingCase {
  GroundTruth truth;
  SparseModel model;
  Similarity rec_from_gt;
};

// The scene's object as the ground truth, and a "reconstruction" of it in another frame whose
// photos began `turn` shots into the plan: image i stands where shot i + turn was planned.
RingCase ring_case(int turn) {
  DiagnosticEngine diag;
  std::string messages;
  rigc::testing::capture_diagnostics(diag, messages);
  auto scene = compile_scene_text(test_inputs::kStatueScene, "statue.yaml", ".", diag);
  EXPECT_TRUE(scene) << messages;
  RingCase c;
  c.truth.positions = ir::object_frame_positions(scene->object);
  c.truth.triangles = scene->object.mesh.triangles;
  c.truth.planned_eyes = planned_eyes(*scene);
  c.rec_from_gt.scale = 3.7;
  c.rec_from_gt.rotation = Eigen::AngleAxisd(1.2, Vec3(0.3, -0.5, 0.8).normalized()).matrix();
  c.rec_from_gt.translation = Vec3(0.4, -1.1, 2.0);
  const Surface surface(c.truth.positions, c.truth.triangles);
  std::vector<Vec3> samples, normals;
  surface.sample(4000, 11, &samples, &normals);
  for (const auto& p : samples) {
    Point3D point;
    point.position = c.rec_from_gt.apply(p);
    c.model.points.push_back(point);
  }
  const int n = static_cast<int>(c.truth.planned_eyes.size());
  for (int i = 0; i < n; ++i) {
    run::ColmapImage image;
    image.image_id = i + 1;
    image.name = "IMG_" + std::to_string(1000 + i) + ".jpg";
    const Vec3 centre = c.rec_from_gt.apply(c.truth.planned_eyes[(i + turn) % n]);
    image.camera_from_world.block<3, 1>(0, 3) = -centre;  // identity rotation
    c.model.images.push_back(image);
  }
  return c;
}

// How far the alignment puts the ground truth's own vertices from where they are.
double worst_error_m(const Alignment& a, const RingCase& c) {
  double worst = 0;
  for (const auto& p : c.truth.positions) {
    const Vec3 x = p.cast<double>();
    worst = std::max(worst, (a.transform.apply(c.rec_from_gt.apply(x)) - x).norm());
  }
  return worst;
}

TEST(Align, PhotosTakenAsPlannedRegisterFromTheCameraRing) {
  const RingCase c = ring_case(5);
  const Surface surface(c.truth.positions, c.truth.triangles);
  const Alignment a = align_to_ground_truth(EvalOptions{}, c.model, c.truth, surface);
  ASSERT_TRUE(a.ok) << a.failure;
  EXPECT_LT(worst_error_m(a, c), 1e-4) << a.report;
  int ring = 0;
  double right_turn = 1, other_turns = 1;
  for (const auto& start : a.report["starts"]) {
    if (start["from"] != "planned cameras") continue;
    ++ring;
    const double before = start["clipped_mean_distance_before_icp_mm"].get<double>() / 1000;
    if (start["turn"] == 5 && start["reversed"] == false)
      right_turn = before;
    else
      other_turns = std::min(other_turns, before);
  }
  EXPECT_EQ(ring, 3) << a.report;
  EXPECT_LT(right_turn, 1e-6) << a.report;  // the exact fit, closest before any ICP
  EXPECT_GT(other_turns, 1e-4) << a.report;
}

TEST(Align, PhotosNotOneToOneWithThePlanGetNoRingCandidates) {
  RingCase c = ring_case(0);
  c.model.images.pop_back();
  const Surface surface(c.truth.positions, c.truth.triangles);
  const Alignment a = align_to_ground_truth(EvalOptions{}, c.model, c.truth, surface);
  ASSERT_TRUE(a.ok) << a.failure;
  for (const auto& start : a.report["starts"]) EXPECT_EQ(start["from"], "RANSAC");
}

}  // namespace
}  // namespace rigc::eval
