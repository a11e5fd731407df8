// The visibility cache: analyses that differ in exposure alone render no visibility again and
// give what an analysis without the cache gives; other poses, canvases or meshes are not served.
#include "analysis/visibility_cache.h"

#include <gtest/gtest.h>

#include <memory>

#include "analysis/coverage.h"
#include "analysis/coverage_test_support.h"

namespace rigc::analysis {
namespace {

constexpr const char* kRing = "  - turntable: {steps: 6, step: 60deg, camera: {distance: 90cm}}\n";

std::shared_ptr<const scene::StudioScene> studio_of(const ir::Scene& scene) {
  return std::make_shared<const scene::StudioScene>(scene::prepare_studio_scene(scene));
}

TEST(VisibilityCache, AnotherExposureReusesEveryShotsSightAndAnalysesAsWithout) {
  const auto dim = compile_statue_scene(kRing, "{aperture: f/11, shutter: 1/125, iso: 100}");
  const auto bright = compile_statue_scene(kRing, "{aperture: f/4, shutter: 1/30, iso: 3200}");
  ASSERT_TRUE(dim && bright);
  CoverageOptions options;
  options.visibility_scale = 0.15;
  options.keep_sights = true;
  const CoverageResult bright_alone = analyse_coverage(*bright, *studio_of(*bright), options);

  options.visibility_cache = std::make_shared<VisibilityCache>();
  const CoverageResult dim_cached = analyse_coverage(*dim, *studio_of(*dim), options);
  EXPECT_EQ(options.visibility_cache->entries(), 6u);
  EXPECT_EQ(options.visibility_cache->hits(), 0u);
  // A studio prepared again from the other scene: same geometry, other objects.
  const CoverageResult bright_cached = analyse_coverage(*bright, *studio_of(*bright), options);
  EXPECT_EQ(options.visibility_cache->entries(), 6u);
  EXPECT_EQ(options.visibility_cache->hits(), 6u);
  expect_same(bright_cached, bright_alone);
  // The exposure did change the verdicts: the bright scene clips where the dim one does not.
  EXPECT_GT(bright_cached.shots[0].clipped, dim_cached.shots[0].clipped + 0.1);
  EXPECT_EQ(bright_cached.views, dim_cached.views);
}

TEST(VisibilityCache, OtherPosesCanvasesOrMeshesAreNotServed) {
  const auto ring = compile_statue_scene(kRing);
  const auto nearer =
      compile_statue_scene("  - turntable: {steps: 6, step: 60deg, camera: {distance: 80cm}}\n");
  ASSERT_TRUE(ring && nearer);
  const auto studio = studio_of(*ring);
  CoverageOptions options;
  options.visibility_scale = 0.1;
  options.visibility_cache = std::make_shared<VisibilityCache>();
  analyse_coverage(*ring, *studio, options);
  analyse_coverage(*nearer, *studio_of(*nearer), options);
  EXPECT_EQ(options.visibility_cache->hits(), 0u);

  options.visibility_scale = 0.12;
  analyse_coverage(*ring, *studio, options);
  EXPECT_EQ(options.visibility_cache->hits(), 0u);

  scene::StudioScene dented = *studio;
  dented.object.positions[0].z() += 0.01f;
  analyse_coverage(*ring, dented, options);
  EXPECT_EQ(options.visibility_cache->hits(), 0u);
  EXPECT_EQ(options.visibility_cache->entries(), 24u);

  analyse_coverage(*ring, *studio, options);
  EXPECT_EQ(options.visibility_cache->hits(), 6u);
}

TEST(VisibilityCache, TheLeastRecentlyUsedGoFirstBeyondTheCapacity) {
  const auto sight = [](std::size_t faces) {
    auto v = std::make_shared<ShotVisibility>();
    v->seen.assign(faces, 1);
    return v;
  };
  VisibilityCache cache(3000 + 3 * sizeof(ShotVisibility));
  cache.insert("a", sight(1000));
  cache.insert("b", sight(1000));
  EXPECT_TRUE(cache.find("a"));  // a is now the most recent
  cache.insert("c", sight(1000));
  EXPECT_EQ(cache.entries(), 2u);
  EXPECT_FALSE(cache.find("b"));
  EXPECT_TRUE(cache.find("a"));
  EXPECT_TRUE(cache.find("c"));
  EXPECT_LE(cache.bytes(), 3000 + 3 * sizeof(ShotVisibility));
  // One entry larger than the whole capacity is still kept, alone.
  cache.insert("d", sight(10000));
  EXPECT_EQ(cache.entries(), 1u);
  EXPECT_TRUE(cache.find("d"));
}

}  // namespace
}  // namespace rigc::analysis
