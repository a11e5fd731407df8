#include "dslr/exposure.h"

#include <gtest/gtest.h>

#include <cmath>

#include "dslr/dslr_test_support.h"
#include "dslr/pipeline.h"

namespace rigc::dslr {
namespace {

using testing::canon_6d;
using testing::flat_frame;
using testing::mean_of;

constexpr double kScale = 0.05;  // 274 x 182: exposure does not depend on the size

double mean_signal(const ir::Camera& camera, float luminance) {
  const LinearFrame frame = flat_frame(sensor_intrinsics(camera, kScale), luminance, 1.0f);
  return mean_of(develop_frame(camera, frame, ShotParams{}, kScale).linear);
}

TEST(DslrExposure, AbsoluteValueFollowsTheSaturationBasedFormula) {
  ir::Camera camera = canon_6d();  // f/8, 1/125 s, ISO 100
  const double luminance = 500;
  // v = L·t·ISO·q / (78·N²), q = 0.65, written out here rather than taken from the code.
  const double expected = 500 * (1.0 / 125) * 100 * 0.65 / (78 * 8 * 8);
  EXPECT_NEAR(mean_signal(camera, luminance), expected, 1e-6 * expected);
  EXPECT_NEAR(expected, luminance / (1.2 * std::pow(2, ev100(8, 1.0 / 125, 100))), 1e-9);
  EXPECT_NEAR(ev100(8, 1.0 / 125, 100), std::log2(8000.0), 1e-12);
  EXPECT_NEAR(ev100(8, 1.0 / 125, 200), std::log2(8000.0) - 1, 1e-12);
}

TEST(DslrExposure, StopsScaleTheLinearSignal) {
  const ir::Camera base = canon_6d();
  const double v = mean_signal(base, 400);
  ir::Camera slower = base;
  slower.shutter_s *= 2;  // +1 stop
  EXPECT_NEAR(mean_signal(slower, 400) / v, 2.0, 1e-5);
  ir::Camera narrower = base;
  narrower.aperture_f_number *= std::sqrt(2.0);  // -1 stop
  EXPECT_NEAR(mean_signal(narrower, 400) / v, 0.5, 1e-5);
  ir::Camera faster_film = base;
  faster_film.iso *= 2;
  EXPECT_NEAR(mean_signal(faster_film, 400) / v, 2.0, 1e-5);
}

TEST(DslrExposure, MeteredAverageLandsAtTheReflectedLightConstant) {
  // A meter (K = 12.5) sets N²/t = L·ISO/K, which gives v = K·q/78 whatever L is.
  ir::Camera camera = canon_6d();
  const double luminance = 250;
  camera.shutter_s =
      camera.aperture_f_number * camera.aperture_f_number * 12.5 / (luminance * camera.iso);
  EXPECT_NEAR(exposure_scale(camera) * luminance, 12.5 * 0.65 / 78, 1e-9);
}

TEST(DslrExposure, SaturatedSignalClipsAtOne) {
  const ir::Camera camera = canon_6d();
  EXPECT_FLOAT_EQ(mean_signal(camera, 1e6), 1.0f);
}

TEST(DslrExposure, StrayNanOrNegativeRadianceBecomesBlack) {
  const ir::Camera camera = canon_6d();
  const std::vector<float> signal = expose(camera, {NAN, -5, INFINITY, 100});
  EXPECT_EQ(signal[0], 0);
  EXPECT_EQ(signal[1], 0);
  EXPECT_EQ(signal[2], 0);
  EXPECT_FLOAT_EQ(signal[3], 100 * exposure_scale(camera));
}

TEST(DslrExposure, CleanFrameIsExposedWithTheVignettingGainAlike) {
  // A renderer's clean frame skips the exposure pass and takes the scale in the warp: through
  // depth of field, diffraction, distortion and vignetting it must develop as any other frame.
  ir::Camera camera = canon_6d();
  camera.effects.depth_of_field = camera.effects.diffraction = true;
  camera.effects.distortion = camera.effects.vignetting = true;
  camera.distortion.k1 = -0.05;
  camera.vignetting = 0.4;
  const Intrinsics grid = sensor_intrinsics(camera, kScale);
  LinearFrame frame = flat_frame(grid, 0, 1.0f);
  for (int y = 0; y < grid.height; ++y) {
    for (int x = 0; x < grid.width; ++x) {
      const std::size_t p = static_cast<std::size_t>(y) * grid.width + x;
      for (int c = 0; c < 3; ++c) frame.rgb[3 * p + c] = 50.0f + 3.0f * x + 2.0f * y + 40.0f * c;
      frame.depth_m[p] = x < grid.width / 2 ? 1.0f : 3.0f;  // a depth step: one side blurred
    }
  }
  ShotParams shot;
  shot.focus_distance_m = 1;
  const std::vector<float> plain = develop_frame(camera, frame, shot, kScale).linear;
  frame.rgb_clean = true;
  const std::vector<float> clean = develop_frame(camera, frame, shot, kScale).linear;
  ASSERT_EQ(plain.size(), clean.size());
  double largest = 0;
  for (std::size_t i = 0; i < plain.size(); ++i) {
    largest = std::max(largest, std::abs(double(plain[i]) - clean[i]) / std::max(plain[i], 1e-6f));
  }
  EXPECT_LT(largest, 1e-5);
  EXPECT_GT(mean_of(clean), 0.5 * exposure_scale(camera) * 50);  // exposed once, not twice
}

TEST(DslrMotionBlur, LengthIsAngularSpeedTimesLeverArmInPixels) {
  const double omega = 2 * M_PI / 10;  // one turn in 10 s
  EXPECT_NEAR(motion_blur_length_px(omega, 1.0 / 125, 0.1, 0.8, 7642),
              omega / 125 * 0.1 * 7642 / 0.8, 1e-9);
  const ir::Camera camera = canon_6d();
  const double f_px = 0.05 * 5472 / 0.0358;
  EXPECT_NEAR(motion_blur_length_px(camera, 1.0, omega, 0.1, 0.8), omega / 125 * 0.1 * f_px / 0.8,
              1e-6);
  EXPECT_NEAR(motion_blur_length_px(camera, 0.5, omega, 0.1, 0.8),
              0.5 * omega / 125 * 0.1 * f_px / 0.8, 1e-3);
}

}  // namespace
}  // namespace rigc::dslr
