// IncrementalCoverage against a full analysis: adding shots one at a time and taking them back
// gives what analyse_coverage gives for the same shots.
#include <gtest/gtest.h>

#include <memory>

#include "analysis/coverage.h"
#include "compiler/frontend.h"

namespace rigc::analysis {
namespace {

std::shared_ptr<const ir::Scene> compile(const std::string& shots) {
  DiagnosticEngine diag;
  std::string messages;
  diag.set_handler([&](const Diagnostic&, const std::string& m) { messages += m; });
  auto scene = compile_scene_text(R"(rigc: 1
object:
  primitive: {shape: statue, detail: 4}
  fit: {height: 30cm}
  surface: {pattern: speckle, scale: 3mm}
studio:
  turntable: {diameter: 40cm, height: 75cm}
  lights:
    - {type: area, position: [0.6m, -1.2m, 1.2m], size: [50cm, 50cm], power: 80W}
  ambient: 300lx
camera:
  body: canon-6d
  lens: {focal_length: 50mm}
  exposure: {aperture: f/11, shutter: 1/125, iso: 200}
shots:
)" + shots,
                                  "test.yaml", ".", diag);
  EXPECT_TRUE(scene) << messages;
  return scene ? std::make_shared<const ir::Scene>(std::move(*scene)) : nullptr;
}

void expect_same(const CoverageResult& a, const CoverageResult& b) {
  EXPECT_EQ(a.views, b.views);
  EXPECT_EQ(a.usable_views, b.usable_views);
  EXPECT_EQ(a.reconstructable, b.reconstructable);
  EXPECT_EQ(a.first_seen, b.first_seen);
  EXPECT_EQ(a.second_seen, b.second_seen);
  EXPECT_DOUBLE_EQ(a.blur_ratio_95, b.blur_ratio_95);
  ASSERT_EQ(a.shots.size(), b.shots.size());
  // Sums over threads: equal up to the order of the additions.
  const auto near = [](double x, double y) {
    return std::abs(x - y) <= 1e-9 * std::abs(y) + 1e-15;
  };
  for (size_t s = 0; s < a.shots.size(); ++s) {
    const ShotCoverage &x = a.shots[s], &y = b.shots[s];
    EXPECT_TRUE(near(x.visible_area_m2, y.visible_area_m2)) << s;
    EXPECT_TRUE(near(x.new_area_m2, y.new_area_m2)) << s;
    EXPECT_TRUE(near(x.overlap_with_previous, y.overlap_with_previous)) << s;
    EXPECT_TRUE(near(x.seen_1, y.seen_1) && near(x.seen_2, y.seen_2) && near(x.seen_3, y.seen_3))
        << s;
    EXPECT_TRUE(near(x.reconstructable, y.reconstructable)) << s;
    EXPECT_TRUE(near(x.out_of_focus, y.out_of_focus) && near(x.too_oblique, y.too_oblique)) << s;
    EXPECT_DOUBLE_EQ(x.frame_fill, y.frame_fill) << s;
  }
  ASSERT_EQ(a.sights.size(), b.sights.size());
  for (size_t s = 0; s < a.sights.size(); ++s) {
    EXPECT_EQ(a.sights[s].seen, b.sights[s].seen);
    EXPECT_EQ(a.sights[s].usable, b.sights[s].usable);
  }
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
