// IncrementalCoverage against a full analysis: adding shots one at a time and taking them back
// gives what analyse_coverage gives for the same shots.
#include <gtest/gtest.h>

#include <memory>

#include "analysis/coverage.h"
#include "analysis/coverage_test_support.h"

namespace rigc::analysis {
namespace {

std::shared_ptr<const ir::Scene> compile(const std::string& shots) {
  return compile_statue_scene(shots);
}

TEST(CoverageIncremental, AddingAndTakingBackShotsEqualsTheFullAnalysis) {
  const auto ring = compile("  - turntable: {steps: 6, step: 60deg, camera: {distance: 90cm}}\n");
  const auto mixed = compile(
      "  - turntable: {steps: 6, step: 60deg, camera: {distance: 90cm}}\n"
      "  - pose: {position: [0.7m, -0.4m, 1.2m], look_at: object}\n"
      "  - pose: {position: [-0.6m, 0.5m, 1.1m], look_at: object}\n");
  ASSERT_TRUE(ring && mixed);
  const auto studio =
      std::make_shared<const scene::StudioScene>(scene::prepare_studio_scene(*ring));
  CoverageOptions options;
  options.visibility_scale = 0.15;
  options.keep_sights = true;

  IncrementalCoverage incremental(ring, studio, options);
  for (const ir::Shot& shot : ring->shots) incremental.add_shot(shot);
  expect_same(incremental.result(), analyse_coverage(*ring, *studio, options));
  EXPECT_GT(incremental.result().shots.back().reconstructable, 0.3);

  // Take two ring shots back, add the two poses, then take one pose back.
  ASSERT_TRUE(incremental.remove_last_shot());
  ASSERT_TRUE(incremental.remove_last_shot());
  ir::Scene partial = *mixed;
  partial.shots.erase(partial.shots.begin() + 4, partial.shots.begin() + 6);
  incremental.add_shot(partial.shots[4]);
  incremental.add_shot(partial.shots[5]);
  EXPECT_EQ(incremental.shot_count(), 6);
  expect_same(incremental.result(), analyse_coverage(partial, *studio, options));
  ASSERT_TRUE(incremental.remove_last_shot());
  partial.shots.pop_back();
  expect_same(incremental.result(), analyse_coverage(partial, *studio, options));
}

TEST(CoverageIncremental, ShotsBeyondTheUndoDepthCannotBeTakenBack) {
  const auto ring = compile("  - turntable: {steps: 2, step: 90deg, camera: {distance: 90cm}}\n");
  ASSERT_TRUE(ring);
  const auto studio =
      std::make_shared<const scene::StudioScene>(scene::prepare_studio_scene(*ring));
  CoverageOptions options;
  options.visibility_scale = 0.05;
  IncrementalCoverage incremental(ring, studio, options);
  EXPECT_FALSE(incremental.remove_last_shot());
  incremental.add_shot(ring->shots[0]);
  EXPECT_TRUE(incremental.remove_last_shot());
  EXPECT_EQ(incremental.shot_count(), 0);
}

}  // namespace
}  // namespace rigc::analysis
