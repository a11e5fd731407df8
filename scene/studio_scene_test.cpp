#include "scene/studio_scene.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <limits>
#include <random>
#include <set>
#include <sstream>

#include "assets/primitives.h"
#include "compiler/frontend.h"
#include "dslr/buffer_pool.h"
#include "dslr/exposure.h"
#include "dslr/lens.h"
#include "dslr/optics.h"
#include "run/colmap_text.h"
#include "run/manifest.h"
#include "run/run_folder.h"
#include "tests/scene_fixtures.h"
#include "tests/test_support.h"

namespace rigc::scene {
namespace {

using testing::paper_scene;

// The rasterizer reads the speckle and noise patterns eight points at a time: a point's value
// must not depend on its lane, on the points beside it or on a partial last step, resolved and
// faded alike.
TEST(Studio, BatchedPatternsMatchThePointPattern) {
  for (const auto kind :
       {ir::PatternKind::kSpeckle, ir::PatternKind::kNoise, ir::PatternKind::kChecker}) {
    ir::SurfacePattern pattern;
    pattern.kind = kind;
    pattern.scale_m = 0.002;
    pattern.contrast = 0.7;
    pattern.seed = 11;
    constexpr int kPoints = 13;  // one full step of eight and a partial one
    std::array<float, kPoints> x, y, z, batched;
    for (const float footprint_m : {0.0001f, 0.0015f}) {
      for (int start = 0; start < 50; ++start) {
        for (int i = 0; i < kPoints; ++i) {
          // Points on both sides of zero, lattice cells apart and within one cell.
          x[i] = 0.0137f * (start - 25) + 0.00031f * i;
          y[i] = -0.0041f * start + 0.0007f * i;
          z[i] = 0.0029f * start - 0.0011f * i;
        }
        scene::pattern_factors(pattern, x.data(), y.data(), z.data(), kPoints, footprint_m,
                               batched.data());
        for (int i = 0; i < kPoints; ++i) {
          const float one = scene::pattern_factor(pattern, {x[i], y[i], z[i]}, footprint_m);
          ASSERT_NEAR(batched[i], one, 1e-5f)
              << "kind " << static_cast<int>(kind) << " point " << i << " start " << start;
        }
      }
    }
  }
}

// Zooming out must not change a pattern's brightness: where it is resolved (a fine footprint)
// its mean over the surface is the faded value it turns into once finer than a pixel.
TEST(Studio, PatternFactorsWithAFootprintPerPointMatchEachPointAlone) {
  ir::SurfacePattern pattern;
  pattern.kind = ir::PatternKind::kSpeckle;
  pattern.scale_m = 0.002;
  pattern.contrast = 0.7;
  pattern.seed = 9;
  // Footprints from sharp (resolved) through half faded to fully faded, eleven points: one full
  // batch of eight and a partial one.
  constexpr int kPoints = 11;
  std::vector<float> x(kPoints), y(kPoints), z(kPoints), footprint(kPoints), factor(kPoints);
  for (int i = 0; i < kPoints; ++i) {
    x[i] = 0.0031f * i;
    y[i] = 0.01f - 0.0017f * i;
    z[i] = 0.0023f * i * i;
    footprint[i] = 0.0002f * i;
  }
  scene::pattern_factors(pattern, x.data(), y.data(), z.data(), kPoints, footprint.data(),
                         factor.data());
  std::set<float> distinct;
  for (int i = 0; i < kPoints; ++i) {
    EXPECT_EQ(factor[i], scene::pattern_factor(pattern, {x[i], y[i], z[i]}, footprint[i]))
        << "point " << i;
    distinct.insert(factor[i]);
  }
  EXPECT_GT(distinct.size(), 5u);  // the points do differ
}

TEST(Studio, ResolvedPatternsAverageToTheirFadedValue) {
  for (const auto kind :
       {ir::PatternKind::kSpeckle, ir::PatternKind::kNoise, ir::PatternKind::kChecker}) {
    for (const int seed : {5, 77}) {
      ir::SurfacePattern pattern;
      pattern.kind = kind;
      pattern.scale_m = 0.002;
      pattern.contrast = 0.7;
      pattern.seed = seed;
      // Points scattered over about 500 x 500 x 500 lattice cells.
      constexpr int kPoints = 200000;
      std::vector<float> x(kPoints), y(kPoints), z(kPoints), factor(kPoints);
      std::mt19937 random(12345);
      std::uniform_real_distribution<float> coordinate(-0.5f, 0.5f);
      for (int i = 0; i < kPoints; ++i) {
        x[i] = coordinate(random);
        y[i] = coordinate(random);
        z[i] = coordinate(random);
      }
      scene::pattern_factors(pattern, x.data(), y.data(), z.data(), kPoints, 1e-6f, factor.data());
      double mean = 0;
      for (float f : factor) mean += f;
      mean /= kPoints;
      const float faded = scene::pattern_factor(pattern, {0.1f, 0.2f, 0.3f}, 1.0f);
      EXPECT_NEAR(mean, faded, 0.02) << "kind " << static_cast<int>(kind);
      // And the resolved pattern has contrast: it is not the faded value everywhere.
      const auto [lo, hi] = std::minmax_element(factor.begin(), factor.end());
      EXPECT_GT(*hi - *lo, 0.5f * pattern.contrast) << "kind " << static_cast<int>(kind);
    }
  }
}

// The preview filters a pattern as the reference renderers do, a box over the pixel: its factor
// for a pixel is the pattern's mean over the pixel's parallelogram on the surface (measured
// here on a 100 x 100 grid), tilted and stretched pixels alike, and a pixel of no extent is
// the point itself.
TEST(Studio, PatternBoxFilterAveragesThePixelArea) {
  for (const auto kind : {ir::PatternKind::kSpeckle, ir::PatternKind::kChecker}) {
    ir::SurfacePattern pattern;
    pattern.kind = kind;
    pattern.scale_m = 0.002;
    pattern.contrast = 0.7;
    pattern.seed = 3;
    std::mt19937 random(21);
    std::uniform_real_distribution<float> coordinate(-0.05f, 0.05f), side(-0.0008f, 0.0008f);
    double worst = 0, mean_difference = 0;
    constexpr int kPixels = 60, kGrid = 100;
    for (int i = 0; i < kPixels; ++i) {
      const scene::PixelOnSurface pixel{
          {coordinate(random), coordinate(random), coordinate(random)},
          {side(random), side(random), side(random)},
          {side(random), side(random), side(random)}};
      float box = 0;
      scene::pattern_factors_box(pattern, &pixel, 1, &box);
      if (std::max(pixel.dx.norm(), pixel.dy.norm()) > 0.5 * pattern.scale_m) continue;  // fades
      double want = 0;
      for (int j = 0; j < kGrid; ++j) {
        for (int k = 0; k < kGrid; ++k) {
          const Eigen::Vector3f at = pixel.at + ((k + 0.5f) / kGrid - 0.5f) * pixel.dx +
                                     ((j + 0.5f) / kGrid - 0.5f) * pixel.dy;
          want += scene::pattern_factor(pattern, at, 0.0f);
        }
      }
      want /= kGrid * kGrid;
      worst = std::max(worst, std::abs(box - want));
      mean_difference += std::abs(box - want) / kPixels;
    }
    // The checker's hard edges leave a grid's steps; the speckle's soft ones hardly any.
    EXPECT_LT(worst, kind == ir::PatternKind::kChecker ? 0.06 : 0.03)
        << "kind " << static_cast<int>(kind);
    EXPECT_LT(mean_difference, 0.005) << "kind " << static_cast<int>(kind);
    const scene::PixelOnSurface point{{0.01f, -0.02f, 0.003f}, {0, 0, 0}, {0, 0, 0}};
    float factor = 0;
    scene::pattern_factors_box(pattern, &point, 1, &factor);
    EXPECT_EQ(factor, scene::pattern_factor(pattern, point.at, 0.0f));
  }
}

// A draft's box filter of one sample per side is the pattern at the pixel's centre, fading to its
// mean as the point-sampled pattern does where the pixel spans more than half its scale.
TEST(Studio, PatternBoxFilterOfOneSampleIsThePointFaded) {
  ir::SurfacePattern pattern;
  pattern.kind = ir::PatternKind::kSpeckle;
  pattern.scale_m = 0.002;
  pattern.contrast = 0.7;
  std::mt19937 random(8);
  std::uniform_real_distribution<float> coordinate(-0.05f, 0.05f), side(-0.002f, 0.002f);
  int filtered_differs = 0;
  for (int i = 0; i < 200; ++i) {
    const scene::PixelOnSurface pixel{{coordinate(random), coordinate(random), coordinate(random)},
                                      {side(random), side(random), side(random)},
                                      {side(random), side(random), side(random)}};
    float draft = 0, filtered = 0;
    scene::pattern_factors_box(pattern, &pixel, 1, &draft, 1);
    scene::pattern_factors_box(pattern, &pixel, 1, &filtered);
    const float footprint = std::max(pixel.dx.norm(), pixel.dy.norm());
    EXPECT_NEAR(draft, scene::pattern_factor(pattern, pixel.at, footprint), 1e-6) << i;
    filtered_differs += std::abs(draft - filtered) > 1e-3;
  }
  EXPECT_GT(filtered_differs, 20);
}

// The rasterizer lets the triangles of one convex face cover a tile together (a tile with a
// corner in none of them, or an edge crossing it, is rasterized per sample): each face must be
// flat, and its triangles must tile a convex polygon, their areas summing to its hull's.
// The floor and the backdrop are matte cloth: no specular layer to reflect the lights or, in
// Cycles, the ambient room (a black backdrop rendered as a grey wall); the turntable keeps one.
TEST(Studio, TheFloorAndBackdropAreMatteAndTheTurntableIsNot) {
  const scene::StudioScene studio = scene::prepare_studio_scene(paper_scene());
  const scene::Geometry& room = studio.studio;
  ASSERT_GT(room.triangles.size(), static_cast<std::size_t>(studio.closed_studio_triangles));
  for (std::size_t t = 0; t < room.triangles.size(); ++t) {
    const float specular = studio.materials[room.triangle_material[t]].specular;
    if (static_cast<int>(t) < studio.closed_studio_triangles) {
      ASSERT_EQ(specular, 0.5f) << "turntable triangle " << t;
    } else {
      ASSERT_EQ(specular, 0.0f) << "floor or backdrop triangle " << t;
    }
  }
}

TEST(Studio, StudioConvexFacesAreFlatAndConvex) {
  const scene::StudioScene studio = scene::prepare_studio_scene(paper_scene());
  const scene::Geometry& room = studio.studio;
  ASSERT_EQ(room.convex_face.size(), room.triangles.size());
  // Two cylinders (96 side rectangles and two caps each), the floor and the green screen.
  ASSERT_EQ(room.convex_faces, 2 * (96 + 2) + 2);
  for (std::int32_t face = 0; face < room.convex_faces; ++face) {
    SCOPED_TRACE(::testing::Message() << "face " << face);
    std::vector<std::size_t> members;
    for (std::size_t t = 0; t < room.triangles.size(); ++t) {
      if (room.convex_face[t] == face) members.push_back(t);
    }
    ASSERT_FALSE(members.empty());
    const Eigen::Vector3f normal = room.face_normals[members[0]];
    const Eigen::Vector3f origin = room.positions[room.triangles[members[0]][0]];
    const Eigen::Vector3f u = normal.unitOrthogonal(), v = normal.cross(u);
    std::vector<Eigen::Vector2d> points;
    double area = 0;
    for (const std::size_t t : members) {
      EXPECT_GT(room.face_normals[t].dot(normal), 0.99999f);
      std::array<Eigen::Vector2d, 3> corner;
      for (int k = 0; k < 3; ++k) {
        const Eigen::Vector3f p = room.positions[room.triangles[t][k]] - origin;
        EXPECT_NEAR(p.dot(normal), 0, 1e-5);
        corner[k] = Eigen::Vector2d(p.dot(u), p.dot(v));
        points.push_back(corner[k]);
      }
      const Eigen::Vector2d a = corner[1] - corner[0], b = corner[2] - corner[0];
      area += std::abs(a.x() * b.y() - a.y() * b.x()) / 2;
    }
    // The hull by Andrew's monotone chain, then its area.
    std::sort(points.begin(), points.end(), [](const auto& p, const auto& q) {
      return p.x() < q.x() || (p.x() == q.x() && p.y() < q.y());
    });
    auto cross = [](const Eigen::Vector2d& o, const Eigen::Vector2d& a, const Eigen::Vector2d& b) {
      return (a.x() - o.x()) * (b.y() - o.y()) - (a.y() - o.y()) * (b.x() - o.x());
    };
    std::vector<Eigen::Vector2d> hull(2 * points.size());
    std::size_t k = 0;
    for (std::size_t i = 0; i < points.size(); ++i) {
      while (k >= 2 && cross(hull[k - 2], hull[k - 1], points[i]) <= 0) --k;
      hull[k++] = points[i];
    }
    for (std::size_t i = points.size() - 1, lower = k + 1; i-- > 0;) {
      while (k >= lower && cross(hull[k - 2], hull[k - 1], points[i]) <= 0) --k;
      hull[k++] = points[i];
    }
    double hull_area = 0;
    for (std::size_t i = 0; i + 1 < k; ++i) {
      hull_area += (hull[i].x() * hull[i + 1].y() - hull[i + 1].x() * hull[i].y()) / 2;
    }
    EXPECT_NEAR(area, hull_area, 1e-6 * hull_area);
  }
}

// Back faces are skipped only for meshes that bound a solid wound outwards.
TEST(Studio, ClosedOutwardMeshesAreRecognised) {
  const ir::Mesh box = make_primitive(PrimitiveKind::kBox, 1, 0);
  const ir::Mesh statue = make_primitive(PrimitiveKind::kStatue, 4, 7);
  for (const ir::Mesh* mesh : {&box, &statue}) {
    auto triangles = mesh->triangles;
    EXPECT_TRUE(scene::is_closed_outward(mesh->positions, triangles));
    auto open = triangles;
    open.pop_back();
    EXPECT_FALSE(scene::is_closed_outward(mesh->positions, open));  // a hole
    auto inside_out = triangles;
    for (auto& t : inside_out) std::swap(t[1], t[2]);
    EXPECT_FALSE(scene::is_closed_outward(mesh->positions, inside_out));
    auto mixed = triangles;
    std::swap(mixed[0][1], mixed[0][2]);  // one face wound the other way
    EXPECT_FALSE(scene::is_closed_outward(mesh->positions, mixed));
  }
}

}  // namespace
}  // namespace rigc::scene
