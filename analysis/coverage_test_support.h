// Scenes and comparisons the coverage tests share.
#pragma once

#include <gtest/gtest.h>

#include <cmath>
#include <memory>
#include <string>

#include "analysis/coverage.h"
#include "compiler/frontend.h"
#include "tests/test_support.h"

namespace rigc::analysis {

// A statue on a turntable lit from one side, with `shots` (YAML list items) and `exposure`.
inline std::shared_ptr<const ir::Scene> compile_statue_scene(
    const std::string& shots,
    const std::string& exposure = "{aperture: f/11, shutter: 1/125, iso: 200}") {
  DiagnosticEngine diag;
  std::string messages;
  rigc::testing::capture_diagnostics(diag, messages);
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
  exposure: )" + exposure + R"(
shots:
)" + shots,
                                  "test.yaml", ".", diag);
  EXPECT_TRUE(scene) << messages;
  return scene ? std::make_shared<const ir::Scene>(std::move(*scene)) : nullptr;
}

// Two analyses agree face by face and shot by shot.
inline void expect_same(const CoverageResult& a, const CoverageResult& b) {
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
    EXPECT_TRUE(near(x.clipped, y.clipped) && near(x.too_dark, y.too_dark)) << s;
    EXPECT_DOUBLE_EQ(x.frame_fill, y.frame_fill) << s;
  }
  ASSERT_EQ(a.sights.size(), b.sights.size());
  for (size_t s = 0; s < a.sights.size(); ++s) {
    EXPECT_EQ(a.sights[s].seen, b.sights[s].seen);
    EXPECT_EQ(a.sights[s].usable, b.sights[s].usable);
  }
}

}  // namespace rigc::analysis
