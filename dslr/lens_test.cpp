#include "dslr/lens.h"

#include <gtest/gtest.h>

#include <cmath>

#include "dslr/dslr_test_support.h"
#include "dslr/exposure.h"
#include "dslr/pipeline.h"

namespace rigc::dslr {
namespace {

using testing::canon_6d;
using testing::flat_frame;

ir::Distortion opencv_coefficients() {
  ir::Distortion d;
  d.k1 = -0.12;
  d.k2 = 0.05;
  d.p1 = 0.001;
  d.p2 = -0.0007;
  d.k3 = -0.01;
  return d;
}

TEST(DslrDistortion, MatchesTheBrownConradyFormula) {
  const ir::Distortion d = opencv_coefficients();
  const double x = 0.3, y = -0.2, r2 = x * x + y * y;
  const double radial = 1 + d.k1 * r2 + d.k2 * r2 * r2 + d.k3 * r2 * r2 * r2;
  const ir::Vec2 p = distort_normalized(d, x, y);
  EXPECT_NEAR(p.x(), x * radial + 2 * d.p1 * x * y + d.p2 * (r2 + 2 * x * x), 1e-15);
  EXPECT_NEAR(p.y(), y * radial + d.p1 * (r2 + 2 * y * y) + 2 * d.p2 * x * y, 1e-15);
  EXPECT_EQ(distort_normalized(ir::Distortion{}, x, y), ir::Vec2(x, y));
}

TEST(DslrDistortion, UndistortInvertsDistortOverTheImage) {
  const ir::Distortion d = opencv_coefficients();
  const ir::Camera camera = canon_6d();
  double worst = 0;
  for (int j = 0; j <= 40; ++j) {
    for (int i = 0; i <= 60; ++i) {
      // Normalised coordinates of the whole sensor, corners included.
      const double x = (i * camera.width_px / 60.0 - camera.cx) / camera.fx;
      const double y = (j * camera.height_px / 40.0 - camera.cy) / camera.fy;
      ir::Vec2 u;
      ASSERT_TRUE(try_undistort_normalized(d, x, y, &u)) << x << "," << y;
      worst = std::max(worst, (distort_normalized(d, u.x(), u.y()) - ir::Vec2(x, y)).norm());
      const ir::Vec2 back =
          undistort_normalized(d, distort_normalized(d, x, y).x(), distort_normalized(d, x, y).y());
      worst = std::max(worst, (back - ir::Vec2(x, y)).norm());
    }
  }
  EXPECT_LT(worst, 1e-6 / camera.fx);  // 1e-6 px
}

TEST(DslrDistortion, BeyondTheFoldThereIsNoSolution) {
  ir::Distortion d;
  d.k1 = -0.5;  // r_d = r(1 - 0.5 r²) peaks at r = 0.816, r_d = 0.544
  ir::Vec2 u;
  EXPECT_TRUE(try_undistort_normalized(d, 0.5, 0, &u));
  EXPECT_FALSE(try_undistort_normalized(d, 0.6, 0, &u));
}

TEST(DslrRenderGeometry, WithoutDistortionTheCanvasIsTheSensor) {
  ir::Camera camera = canon_6d();
  for (bool effect : {false, true}) {
    camera.effects.distortion = effect;
    camera.distortion = effect ? ir::Distortion{} : opencv_coefficients();
    const RenderGeometry g = render_geometry_for(camera, 0.5);
    EXPECT_EQ(g.width, 2736);
    EXPECT_EQ(g.height, 1824);
    EXPECT_DOUBLE_EQ(g.fx, camera.fx / 2);
    EXPECT_DOUBLE_EQ(g.cx, 1368);
    EXPECT_FALSE(g.clipped);
  }
}

// A strong tangential term the compiler accepts (no fold-over before the frame's edge) still
// asks for more canvas than the cap of twice the sensor: the geometry says so.
TEST(DslrRenderGeometry, TheCapIsReportedAsClipped) {
  ir::Camera camera = canon_6d();
  camera.effects.distortion = true;
  camera.distortion = {0.056, -0.0025, -0.027, -0.24, 0.046};
  const RenderGeometry g = render_geometry_for(camera, 0.25);
  EXPECT_TRUE(g.clipped);
  EXPECT_EQ(g.width, 2 * 1368);
}

TEST(DslrRenderGeometry, EverySensorPixelMapsInsideTheCanvas) {
  ir::Camera camera = canon_6d();
  camera.effects.distortion = true;
  for (double k1 : {-0.2, 0.15}) {
    camera.distortion = opencv_coefficients();
    camera.distortion.k1 = k1;
    const double scale = 0.25;
    const Intrinsics s = sensor_intrinsics(camera, scale);
    const RenderGeometry g = render_geometry_for(camera, scale);
    EXPECT_FALSE(g.clipped);
    EXPECT_DOUBLE_EQ(g.fx, s.fx);
    EXPECT_NEAR(g.cx - g.width / 2.0, s.cx - s.width / 2.0, 1e-9);  // centred stays centred
    if (k1 < 0) {
      EXPECT_GT(g.width, s.width);  // barrel: the corners come from further out
    }
    double u_min = 1e9, u_max = -1e9, v_min = 1e9, v_max = -1e9;
    for (int j = 0; j < s.height; ++j) {
      for (int i = 0; i < s.width; ++i) {
        if (j != 0 && j != s.height - 1 && i != 0 && i != s.width - 1 && (i + j) % 7 != 0) continue;
        const ir::Vec2 u = undistort_normalized(camera.distortion, (i + 0.5 - s.cx) / s.fx,
                                                (j + 0.5 - s.cy) / s.fy);
        u_min = std::min(u_min, g.fx * u.x() + g.cx), u_max = std::max(u_max, g.fx * u.x() + g.cx);
        v_min = std::min(v_min, g.fy * u.y() + g.cy), v_max = std::max(v_max, g.fy * u.y() + g.cy);
      }
    }
    // Inside with room for the bilinear footprint (pixel centres at +0.5).
    EXPECT_GE(u_min, 1.0) << k1;
    EXPECT_LE(u_max, g.width - 1.0) << k1;
    EXPECT_GE(v_min, 1.0) << k1;
    EXPECT_LE(v_max, g.height - 1.0) << k1;
    EXPECT_LT(u_min, 6.0) << k1;  // and not much more than that
  }
}

TEST(DslrDistortion, WarpedDotsLandWhereDistortSays) {
  ir::Camera camera = canon_6d();
  camera.effects.distortion = true;
  camera.distortion = opencv_coefficients();
  const double scale = 0.125;
  const RenderGeometry g = render_geometry_for(camera, scale);
  LinearFrame frame = flat_frame(g, 0, 1.0f);
  // Gaussian dots (σ 1.2 px) on a grid of the undistorted canvas.
  std::vector<ir::Vec2> dots;
  for (double v = 20; v < g.height - 20; v += 40) {
    for (double u = 20; u < g.width - 20; u += 40) dots.emplace_back(u + 0.3, v + 0.7);
  }
  for (int y = 0; y < g.height; ++y) {
    for (int x = 0; x < g.width; ++x) {
      double value = 0;
      for (const ir::Vec2& dot : dots) {
        const double dx = x + 0.5 - dot.x(), dy = y + 0.5 - dot.y();
        if (dx * dx + dy * dy < 36) value += std::exp(-(dx * dx + dy * dy) / (2 * 1.2 * 1.2));
      }
      for (int c = 0; c < 3; ++c)
        frame.rgb[3 * (static_cast<std::size_t>(y) * g.width + x) + c] = 5000 * value;
    }
  }
  const DevelopResult r = develop_frame(camera, frame, {1, 0, 1}, scale);
  const Intrinsics s = sensor_intrinsics(camera, scale);
  int checked = 0;
  double worst = 0;
  for (const ir::Vec2& dot : dots) {
    const ir::Vec2 xd =
        distort_normalized(camera.distortion, (dot.x() - g.cx) / g.fx, (dot.y() - g.cy) / g.fy);
    const double eu = s.fx * xd.x() + s.cx, ev = s.fy * xd.y() + s.cy;  // expected, continuous
    if (eu < 8 || ev < 8 || eu > s.width - 8 || ev > s.height - 8) continue;
    double sum = 0, su = 0, sv = 0;
    for (int y = static_cast<int>(ev) - 5; y <= static_cast<int>(ev) + 5; ++y) {
      for (int x = static_cast<int>(eu) - 5; x <= static_cast<int>(eu) + 5; ++x) {
        const double value = r.linear[3 * (static_cast<std::size_t>(y) * s.width + x) + 1];
        sum += value, su += value * (x + 0.5), sv += value * (y + 0.5);
      }
    }
    ASSERT_GT(sum, 0);
    worst = std::max(worst, std::hypot(su / sum - eu, sv / sum - ev));
    ++checked;
  }
  EXPECT_GT(checked, 100);
  EXPECT_LT(worst, 0.5);
}

TEST(DslrDistortion, WarpSamplesTheExactUndistortedPosition) {
  // A canvas whose colour is its own pixel position: bilinear sampling of a ramp is exact, so the
  // warped colour is where the warp sampled, to compare with a Newton solve per pixel.
  ir::Camera camera = canon_6d();
  camera.effects.distortion = true;
  camera.distortion = opencv_coefficients();
  camera.distortion.k1 = -0.2;
  const double scale = 0.125;  // the coarsest map relative to the image: the worst case
  const RenderGeometry g = render_geometry_for(camera, scale);
  std::vector<float> ramp(3 * static_cast<std::size_t>(g.width) * g.height);
  for (int y = 0; y < g.height; ++y) {
    for (int x = 0; x < g.width; ++x) {
      float* p = &ramp[3 * (static_cast<std::size_t>(y) * g.width + x)];
      p[0] = static_cast<float>(x), p[1] = static_cast<float>(y), p[2] = 0;
    }
  }
  const Intrinsics s = sensor_intrinsics(camera, scale);
  const SensorImage warped = warp_to_sensor(camera, s, g, ramp, {}, {});
  double worst = 0;
  for (int j = 0; j < s.height; ++j) {
    for (int i = 0; i < s.width; ++i) {
      const ir::Vec2 u =
          undistort_normalized(camera.distortion, (i + 0.5 - s.cx) / s.fx, (j + 0.5 - s.cy) / s.fy);
      const float* p = &warped.rgb[3 * (static_cast<std::size_t>(j) * s.width + i)];
      worst = std::max(worst, std::hypot(p[0] - (g.fx * u.x() + g.cx - 0.5),
                                         p[1] - (g.fy * u.y() + g.cy - 0.5)));
    }
  }
  EXPECT_LT(worst, 0.01);
}

TEST(DslrDistortion, WarpTakesDepthAndMaskFromTheNearestCanvasPixel) {
  // Colour, depth and mask all ramps of the canvas position: the warped colour says where the
  // warp sampled, and depth and mask must come from the canvas pixel nearest to that. A mild
  // lens (most cells take the eight-pixel path) and a strong one (many fall back per pixel).
  for (const double k1 : {-0.02, -0.2}) {
    ir::Camera camera = canon_6d();
    camera.effects.distortion = true;
    camera.effects.vignetting = false;
    camera.distortion = opencv_coefficients();
    camera.distortion.k1 = k1;
    const double scale = 0.25;
    const RenderGeometry g = render_geometry_for(camera, scale);
    const std::size_t n = static_cast<std::size_t>(g.width) * g.height;
    std::vector<float> ramp(3 * n), depth(n);
    std::vector<std::uint8_t> mask(n);
    auto mask_at = [](int x, int y) { return static_cast<std::uint8_t>((7 * x + 13 * y) & 255); };
    for (int y = 0; y < g.height; ++y) {
      for (int x = 0; x < g.width; ++x) {
        const std::size_t p = static_cast<std::size_t>(y) * g.width + x;
        ramp[3 * p] = static_cast<float>(x), ramp[3 * p + 1] = static_cast<float>(y);
        depth[p] = static_cast<float>(1 + p);
        mask[p] = mask_at(x, y);
      }
    }
    const Intrinsics s = sensor_intrinsics(camera, scale);
    const SensorImage warped = warp_to_sensor(camera, s, g, ramp, depth, mask);
    int checked = 0, wrong = 0;
    for (std::size_t p = 0; p < static_cast<std::size_t>(s.width) * s.height; ++p) {
      const float u = warped.rgb[3 * p], v = warped.rgb[3 * p + 1];
      // Halfway between two pixels the ramp's rounding could pick either: skip those.
      if (std::abs(u - std::floor(u) - 0.5f) < 1e-3f || std::abs(v - std::floor(v) - 0.5f) < 1e-3f)
        continue;
      const int x = std::clamp(static_cast<int>(std::floor(u + 0.5f)), 0, g.width - 1);
      const int y = std::clamp(static_cast<int>(std::floor(v + 0.5f)), 0, g.height - 1);
      ++checked;
      wrong +=
          warped.depth_m[p] != static_cast<float>(1 + static_cast<std::size_t>(y) * g.width + x) ||
          warped.mask[p] != mask_at(x, y);
    }
    EXPECT_GT(checked, s.width * s.height * 9 / 10) << "k1 " << k1;
    EXPECT_EQ(wrong, 0) << "k1 " << k1;
  }
}

TEST(DslrVignetting, CornersLoseTheConfiguredFraction) {
  ir::Camera camera = canon_6d();
  camera.effects.vignetting = true;
  camera.vignetting = 0.4;
  const double scale = 0.1;
  const Intrinsics s = sensor_intrinsics(camera, scale);
  const DevelopResult r = develop_frame(camera, flat_frame(s, 500, 1.0f), {1, 0, 1}, scale);
  auto at = [&](int x, int y) {
    return r.linear[3 * (static_cast<std::size_t>(y) * s.width + x) + 1];
  };
  const double centre = at(s.width / 2, s.height / 2);
  EXPECT_NEAR(at(0, 0) / centre, 0.6, 0.01);
  EXPECT_NEAR(at(s.width - 1, s.height - 1) / centre, 0.6, 0.01);
  EXPECT_GT(at(s.width / 4, s.height / 2) / centre, at(0, s.height / 2) / centre);
  // In between, the shape is cos⁴ of the field angle: 1/(1 + r²)² for normalised radius r.
  const double xc = (0 - s.cx) / s.fx, yc = (0 - s.cy) / s.fy;
  const int i = s.width * 3 / 4, j = s.height / 2;
  const double x = (i + 0.5 - s.cx) / s.fx, y = (j + 0.5 - s.cy) / s.fy;
  auto cos4 = [](double r2) { return 1 / ((1 + r2) * (1 + r2)); };
  const double expected = 1 - 0.4 * (1 - cos4(x * x + y * y)) / (1 - cos4(xc * xc + yc * yc));
  EXPECT_NEAR(at(i, j) / centre, expected, 1e-4);
  EXPECT_DOUBLE_EQ(vignetting_gain(0.4, 0, 0.3), 1.0);
  EXPECT_DOUBLE_EQ(vignetting_gain(0.4, 0.3, 0.3), 0.6);
}

TEST(DslrDistortion, MaskAndDepthFollowTheImage) {
  ir::Camera camera = canon_6d();
  camera.effects.distortion = true;
  camera.distortion.k1 = -0.15;
  const double scale = 0.1;
  const RenderGeometry g = render_geometry_for(camera, scale);
  LinearFrame frame = flat_frame(g, 0, 5.0f);
  frame.mask.assign(static_cast<std::size_t>(g.width) * g.height, 0);
  // A bright square with its mask and depth.
  for (int y = 10; y < 40; ++y) {
    for (int x = 10; x < 60; ++x) {
      const std::size_t p = static_cast<std::size_t>(y) * g.width + x;
      frame.mask[p] = 255;
      frame.depth_m[p] = 1.0f;
      for (int c = 0; c < 3; ++c) frame.rgb[3 * p + c] = 5000;
    }
  }
  const DevelopResult r = develop_frame(camera, frame, {1, 0, 1}, scale);
  ASSERT_EQ(r.mask.size(), static_cast<std::size_t>(r.width) * r.height);
  int agree = 0, masked = 0;
  for (std::size_t p = 0; p < r.mask.size(); ++p) {
    if (r.mask[p] == 0) continue;
    ++masked;
    agree += r.linear[3 * p + 1] > 0.25f * 5000 * exposure_scale(camera) && r.depth_m[p] == 1.0f;
  }
  EXPECT_GT(masked, 500);
  EXPECT_GT(agree, 0.95 * masked);
}

}  // namespace
}  // namespace rigc::dslr
