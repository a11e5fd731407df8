#include "plan/candidates.h"

#include <fmt/format.h>
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "compiler/check.h"
#include "compiler/frontend.h"
#include "tests/test_support.h"

using ::testing::HasSubstr;

namespace rigc::plan {
namespace {

std::string scene_with(const std::string& shots) {
  return "rigc: 1\n"
         "object: {primitive: sphere, fit: {height: 20cm}, surface: {pattern: speckle}}\n"
         "camera:\n"
         "  body: canon-6d\n"
         "  lens: {focal_length: 50mm}\n"
         "  exposure: {aperture: f/8, shutter: 1/125, iso: 200}\n" +
         shots;
}

// A pose given by a rotation (a real camera's) is planned as written: its position and rotation
// to the last digit, not rounded to a tenth of a millimetre nor turned into a look_at.
TEST(Candidates, RotationPoseIsWrittenBackExactly) {
  const Eigen::Matrix3d r =
      (Eigen::AngleAxisd(0.3, ir::Vec3::UnitZ()) * Eigen::AngleAxisd(-1.7, ir::Vec3::UnitX()))
          .toRotationMatrix()
          .transpose();
  const std::string shots = fmt::format(
      "shots:\n  - pose: {{position: [0.312345678m, -0.62m, 1.07m], rotation: [[{}, {}, {}], [{}, "
      "{}, {}], [{}, {}, {}]]}}\n",
      r(0, 0), r(0, 1), r(0, 2), r(1, 0), r(1, 1), r(1, 2), r(2, 0), r(2, 1), r(2, 2));
  DiagnosticEngine diag;
  std::string messages;
  rigc::testing::capture_diagnostics(diag, messages);
  const std::string text = scene_with(shots);
  const auto root = parse_yaml(text, "test.yaml", diag);
  ASSERT_TRUE(root) << messages;
  const auto spec = check_scene(*root, "test.yaml", ".", diag);
  ASSERT_TRUE(spec) << messages;
  const auto scene = lower_scene(*spec, diag);
  ASSERT_TRUE(scene) << messages;
  CandidateOptions options;
  options.turntable_only = true;
  const CandidateSet set = make_candidates(*spec, *scene, options);
  const std::string planned = shots_yaml(set, all_candidates(set), true);
  EXPECT_THAT(planned, HasSubstr("rotation: [["));
  const auto again = compile_scene_text(scene_with(planned), "planned.yaml", ".", diag);
  ASSERT_TRUE(again) << messages << planned;
  ASSERT_EQ(again->shots.size(), 1u);
  EXPECT_LT(
      (again->shots[0].world_from_camera - scene->shots[0].world_from_camera).cwiseAbs().maxCoeff(),
      1e-12)
      << planned;
}

}  // namespace
}  // namespace rigc::plan
