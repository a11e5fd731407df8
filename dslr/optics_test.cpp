#include "dslr/optics.h"

#include <gtest/gtest.h>

#include <cmath>
#include <functional>
#include <set>

#include "dslr/dslr_test_support.h"
#include "dslr/exposure.h"
#include "dslr/pipeline.h"

namespace rigc::dslr {
namespace {

using testing::canon_6d;
using testing::flat_frame;

// Fraction of a disc of radius 1 to the left of x = a.
double disc_edge_fraction(double a) {
  return 0.5 + (a * std::sqrt(1 - a * a) + std::asin(a)) / M_PI;
}

// The 10-90 % width of the edge spread of a uniform disc, as a fraction of its diameter: the
// disc's edge spread is the area of the disc left of a line, so it is 2·a90 with F(a90) = 0.9.
double disc_10_90_width_over_diameter() {
  double lo = 0, hi = 1;
  for (int i = 0; i < 60; ++i) {
    const double mid = 0.5 * (lo + hi);
    (disc_edge_fraction(mid) < 0.9 ? lo : hi) = mid;
  }
  return lo;  // 2·a90 over the diameter 2
}

// Distance between the 10 % and 90 % crossings of a monotonic edge profile, linearly
// interpolated between pixel centres.
double width_10_90(const std::vector<double>& profile) {
  const double low = profile.front(), high = profile.back();
  auto crossing = [&](double level) {
    const double target = low + level * (high - low);
    for (std::size_t i = 1; i < profile.size(); ++i) {
      const double a = profile[i - 1] - target, b = profile[i] - target;
      if ((a <= 0) != (b <= 0)) return (i - 1) + a / (a - b);
    }
    return -1.0;
  };
  return std::abs(crossing(0.9) - crossing(0.1));
}

struct EdgeScene {
  ir::Camera camera;
  double scale;
  LinearFrame frame;
};

// Sets every channel of the frame's columns from width/2 on to `value`.
void brighten_right_half(LinearFrame& frame, float value) {
  for (int y = 0; y < frame.height; ++y) {
    for (int x = frame.width / 2; x < frame.width; ++x) {
      for (int c = 0; c < 3; ++c)
        frame.rgb[3 * (static_cast<std::size_t>(y) * frame.width + x) + c] = value;
    }
  }
}

// Dark on the left, bright from column width/2 on, every pixel at depth_m.
EdgeScene step_edge(double f_number, double depth_m, double scale) {
  EdgeScene s{canon_6d(), scale, {}};
  s.camera.aperture_f_number = f_number;
  s.camera.effects.depth_of_field = true;
  s.frame = flat_frame(sensor_intrinsics(s.camera, scale), 100, static_cast<float>(depth_m));
  brighten_right_half(s.frame, 1000);
  return s;
}

// Mean over the middle rows of the green channel, columns [x0, x1).
std::vector<double> row_profile(const DevelopResult& r, int x0, int x1) {
  std::vector<double> profile;
  for (int x = x0; x < x1; ++x) {
    double sum = 0;
    for (int y = r.height / 2 - 10; y < r.height / 2 + 10; ++y) {
      sum += r.linear[3 * (static_cast<std::size_t>(y) * r.width + x) + 1];
    }
    profile.push_back(sum / 20);
  }
  return profile;
}

constexpr double kFocus = 0.8;

TEST(DslrDepthOfField, CircleOfConfusionFollowsTheThinLens) {
  // c = (f/N)·f·|S2 - S1| / (S2·(S1 - f))
  EXPECT_NEAR(coc_diameter_m(0.05, 2.8, 0.8, 2.0), 0.05 / 2.8 * 0.05 * 1.2 / (2.0 * 0.75), 1e-12);
  EXPECT_NEAR(coc_diameter_m(0.05, 8, 0.8, INFINITY), 0.05 / 8 * 0.05 / 0.75, 1e-12);
  EXPECT_EQ(coc_diameter_m(0.05, 8, 0.8, 0.8), 0);
  // In the pinhole picture: (S1 - f)/S1 of it, (f/N)·f·|S2 - S1|/(S2·S1).
  EXPECT_NEAR(coc_in_image_m(0.05, 2.8, 0.8, 2.0), 0.05 / 2.8 * 0.05 * 1.2 / (2.0 * 0.8), 1e-12);
  EXPECT_EQ(coc_in_image_m(0.05, 8, 0.04, 2.0), 0);
  EXPECT_EQ(coc_in_image_m(0.05, 8, 0, 2.0), 0);
  EXPECT_NEAR(hyperfocal_m(0.05, 8, 0.03e-3), 0.0025 / (8 * 0.03e-3) + 0.05, 1e-9);
  // At the hyperfocal distance, infinity is blurred by exactly c0.
  EXPECT_NEAR(coc_diameter_m(0.05, 8, hyperfocal_m(0.05, 8, 0.03e-3), INFINITY), 0.03e-3, 1e-9);
}

TEST(DslrDepthOfField, EdgeAtTheFocusDistanceStaysSharp) {
  EdgeScene s = step_edge(2.8, kFocus, 0.125);
  const DevelopResult r = develop_frame(s.camera, s.frame, {kFocus, 0, 1}, s.scale);
  const int mid = r.width / 2;
  EXPECT_LT(width_10_90(row_profile(r, mid - 20, mid + 20)), 1.0);
}

// The measured 10-90 % width of a blurred edge equals that of a disc of the thin-lens diameter.
void expect_disc_blur(double depth_m, double scale, double min_diameter_px) {
  EdgeScene s = step_edge(2.8, depth_m, scale);
  const double pitch_m = s.camera.sensor_width_m / std::lround(s.camera.width_px * scale);
  const double diameter_px =
      0.05 / 2.8 * 0.05 * std::abs(depth_m - kFocus) / (depth_m * (kFocus - 0.05)) / pitch_m;
  ASSERT_GT(diameter_px, min_diameter_px);  // the test means something
  const DevelopResult r = develop_frame(s.camera, s.frame, {kFocus, 0, 1}, s.scale);
  const int mid = r.width / 2, half = static_cast<int>(diameter_px) + 4;
  const double measured = width_10_90(row_profile(r, mid - half, mid + half));
  const double expected = disc_10_90_width_over_diameter() * diameter_px;
  EXPECT_NEAR(measured, expected, 0.15 * expected) << "CoC diameter " << diameter_px << " px";
}

TEST(DslrDepthOfField, BlurWidthMatchesTheCircleOfConfusion) {
  EXPECT_NEAR(disc_10_90_width_over_diameter(), 0.687, 0.001);
  expect_disc_blur(1.3, 0.125, 8);   // ~8.8 px: the dense taps
  expect_disc_blur(3.0, 0.25, 30);   // ~33 px: the ring taps
  expect_disc_blur(0.5, 0.125, 12);  // ~13.6 px, in front of the focus
  expect_disc_blur(20.0, 0.5, 80);   // ~87 px: gathered three levels down, at an eighth
}

// The 1-D variance of the line spread of a vertical step edge blurred by apply_depth_of_field
// on a small canvas at one depth, the edge between columns width/2 - 1 and width/2.
double edge_spread_variance(const ir::Camera& camera, double depth_m) {
  const Intrinsics canvas{64, 16, 1000, 1000, 32, 8};
  LinearFrame frame = flat_frame(canvas, 0, static_cast<float>(depth_m));
  brighten_right_half(frame, 1);
  std::vector<float> out;
  apply_depth_of_field(camera, kFocus, canvas, frame.rgb, frame.depth_m, out);
  const int row = canvas.height / 2;
  double weight = 0, first = 0, second = 0;
  for (int x = 1; x < canvas.width; ++x) {
    const std::size_t at = 3 * (static_cast<std::size_t>(row) * canvas.width + x) + 1;
    const double spread = out[at] - out[at - 3];  // between x - 1 and x: at x - 0.5
    weight += spread;
    first += spread * (x - 0.5);
    second += spread * (x - 0.5) * (x - 0.5);
  }
  const double mean = first / weight;
  return second / weight - mean * mean;
}

TEST(DslrDepthOfField, DiscsOfAPixelOrTwoSpreadAnEdgeAsTheThinLensDoes) {
  // The paper scene's discs at f/5.6 at a quarter scale: a disc of radius r spreads an edge
  // with variance r²/4 (the canvas pixels' own box is the render's, not the blur's).
  ir::Camera camera = canon_6d();
  camera.aperture_f_number = 2.8;
  const double f = camera.focal_length_m, fx = 1000;
  for (double r = 0.5; r <= 4.0; r += 0.125) {
    // coc_in_image_m = (f/N)·f·(z - S1)/(z·S1) = 2r·f/fx, for z behind the focus.
    const double coc = 2 * r * f / fx;
    const double depth = 1 / (1 / kFocus - coc / (f / camera.aperture_f_number * f));
    ASSERT_NEAR(0.5 * coc_in_image_m(f, camera.aperture_f_number, kFocus, depth) * fx / f, r, 1e-9);
    const double variance = edge_spread_variance(camera, depth);
    EXPECT_NEAR(variance, r * r / 4, 0.04 * r * r / 4) << "disc radius " << r << " px";
  }
}

TEST(DslrDepthOfField, SharpForegroundKeepsItsValuesNextToABlurredBackground) {
  ir::Camera camera = canon_6d();
  camera.aperture_f_number = 2.8;
  camera.effects.depth_of_field = true;
  const double scale = 0.125;
  LinearFrame frame = flat_frame(sensor_intrinsics(camera, scale), 0, 3.0f);
  const int w = frame.width, h = frame.height, edge = w / 2;
  for (int y = 0; y < h; ++y) {
    for (int x = 0; x < w; ++x) {
      float* p = &frame.rgb[3 * (static_cast<std::size_t>(y) * w + x)];
      if (x < edge) {  // a red, textured foreground in focus
        p[0] = 300 + 200 * ((x / 3 + y / 3) % 2);
        frame.depth_m[static_cast<std::size_t>(y) * w + x] = kFocus;
      } else {  // a blue, striped background far behind it
        p[2] = 1000 * ((x / 4) % 2);
      }
    }
  }
  ir::Camera sharp = camera;
  sharp.effects.depth_of_field = false;
  const DevelopResult blurred = develop_frame(camera, frame, {kFocus, 0, 1}, scale);
  const DevelopResult reference = develop_frame(sharp, frame, {kFocus, 0, 1}, scale);
  for (int y = 0; y < h; ++y) {
    for (int x = 0; x < w; ++x) {
      const std::size_t p = 3 * (static_cast<std::size_t>(y) * w + x);
      if (x < edge) {
        for (int c = 0; c < 3; ++c) {
          ASSERT_FLOAT_EQ(blurred.linear[p + c], reference.linear[p + c]) << x << "," << y;
        }
      } else {
        ASSERT_LT(blurred.linear[p], 1e-6) << "foreground red bled onto the background at " << x;
      }
    }
  }
  // The background really is blurred: its 4-pixel stripes average to half their peak.
  const double peak = 1000 * exposure_scale(camera);
  for (int x = edge + 30; x < edge + 40; ++x) {
    const std::size_t p = 3 * (static_cast<std::size_t>(h / 2) * w + x);
    EXPECT_NEAR(blurred.linear[p + 2], 0.5 * peak, 0.1 * peak) << x;
  }
}

// Tiles whose whole neighbourhood is flat are copied rather than gathered. A faint texture (2 %
// stripes) on a far backdrop must still be blurred, and a smooth ramp, which a blur leaves as it
// is, must stay within the flat tolerance of itself.
TEST(DslrDepthOfField, FaintTextureIsBlurredAndSmoothRampsKeepTheirValues) {
  ir::Camera camera = canon_6d();
  camera.aperture_f_number = 2.8;
  camera.effects.depth_of_field = true;
  const Intrinsics canvas = sensor_intrinsics(camera, 0.25);
  LinearFrame striped = flat_frame(canvas, 0, 3.0f), ramp = flat_frame(canvas, 0, 3.0f);
  const int w = canvas.width, h = canvas.height;
  for (int y = 0; y < h; ++y) {
    for (int x = 0; x < w; ++x) {
      const std::size_t p = 3 * (static_cast<std::size_t>(y) * w + x);
      for (int c = 0; c < 3; ++c) {
        striped.rgb[p + c] = 500 * (1 + 0.02f * ((x / 4) % 2));
        ramp.rgb[p + c] = 500 + 0.1f * x + 0.05f * y;  // 0.02 % of the value per pixel
      }
    }
  }
  std::vector<float> out;
  apply_depth_of_field(camera, kFocus, canvas, striped.rgb, striped.depth_m, out);
  double lo = 1e9, hi = 0;
  for (int x = w / 2; x < w / 2 + 16; ++x) {
    const float v = out[3 * (static_cast<std::size_t>(h / 2) * w + x)];
    lo = std::min<double>(lo, v);
    hi = std::max<double>(hi, v);
  }
  EXPECT_LT(hi - lo, 0.2 * 0.02 * 500) << "the stripes' 2 % contrast should mostly blur away";
  apply_depth_of_field(camera, kFocus, canvas, ramp.rgb, ramp.depth_m, out);
  double worst = 0;
  for (int y = h / 4; y < 3 * h / 4; ++y) {
    for (int x = w / 4; x < 3 * w / 4; ++x) {
      const std::size_t p = 3 * (static_cast<std::size_t>(y) * w + x);
      worst = std::max(worst, std::abs(out[p] - ramp.rgb[p]) / double(ramp.rgb[p]));
    }
  }
  EXPECT_LT(worst, 0.004);
}

TEST(DslrDepthOfField, BlurredForegroundSpreadsOverASharpBackground) {
  ir::Camera camera = canon_6d();
  camera.aperture_f_number = 2.8;
  camera.effects.depth_of_field = true;
  const double scale = 0.125;
  LinearFrame frame = flat_frame(sensor_intrinsics(camera, scale), 0, kFocus);
  const int w = frame.width, h = frame.height, edge = w / 2;
  for (int y = 0; y < h; ++y) {
    for (int x = 0; x < w; ++x) {
      float* p = &frame.rgb[3 * (static_cast<std::size_t>(y) * w + x)];
      if (x < edge) {  // red foreground, far in front of the focus
        p[0] = 1000;
        frame.depth_m[static_cast<std::size_t>(y) * w + x] = 0.4f;
      } else {
        p[2] = 1000;  // blue background in focus
      }
    }
  }
  const double pitch_m = camera.sensor_width_m / w;
  const double radius_px = 0.5 * coc_in_image_m(0.05, 2.8, kFocus, 0.4) / pitch_m;
  ASSERT_GT(radius_px, 8);
  const DevelopResult r = develop_frame(camera, frame, {kFocus, 0, 1}, scale);
  const double peak = 1000 * exposure_scale(camera);
  auto red_at = [&](int x) { return r.linear[3 * (static_cast<std::size_t>(h / 2) * w + x)]; };
  auto blue_at = [&](int x) { return r.linear[3 * (static_cast<std::size_t>(h / 2) * w + x) + 2]; };
  // Across the edge the blur is symmetric (half and half at the edge) and conserves light.
  EXPECT_NEAR(red_at(edge) / peak, 0.45, 0.1);
  for (int x = edge - 20; x < edge + 20; ++x) EXPECT_NEAR((red_at(x) + blue_at(x)) / peak, 1, 0.02);
  EXPECT_GT(red_at(edge + static_cast<int>(radius_px / 2)) / peak, 0.02);
  // Just inside the edge, the background shows through the blurred foreground's edge.
  EXPECT_NEAR(red_at(edge - 1) / peak, 0.6, 0.15);
  EXPECT_NEAR(blue_at(edge - 1) / peak, 0.4, 0.15);
  // Beyond its disc the background is untouched.
  EXPECT_EQ(red_at(edge + static_cast<int>(radius_px) + 2), 0);
  EXPECT_NEAR(red_at(edge - static_cast<int>(radius_px) - 2) / peak, 1, 1e-5);
}

// Where a blurred foreground, a sharp subject and a blurred background meet, each group of
// eight pixels gathers only the taps that can weigh anything for it, in one layer where nothing
// in front or behind can weigh (DepthOfFieldOptions): the sums, and so every value, must be those
// of the tile's full tap count in three layers.
TEST(DslrDepthOfField, TapsPerGroupGiveTheTilesResult) {
  ir::Camera camera = canon_6d();
  camera.aperture_f_number = 2.8;
  const double scale = 0.125;
  LinearFrame frame = flat_frame(sensor_intrinsics(camera, scale), 0, 3.0f);
  const int w = frame.width, h = frame.height;
  for (int y = 0; y < h; ++y) {
    for (int x = 0; x < w; ++x) {
      const std::size_t p = static_cast<std::size_t>(y) * w + x;
      float* rgb = &frame.rgb[3 * p];
      // Left to right: subject, a bar in front of it, subject, background (and a band of
      // background along the top), so some groups see only the bar's discs, some only the
      // background's, some both.
      const bool subject = x < 3 * w / 4 && y > h / 6;
      const bool near = x > w / 4 && x < w / 3 && y > h / 3;
      if (near) {  // a blurred bar in front of the subject
        frame.depth_m[p] = 0.45f;
        rgb[0] = 900, rgb[1] = 300 + 200 * ((y / 3) % 2), rgb[2] = 100;
      } else if (subject) {  // the sharp subject at the focus distance, finely striped
        frame.depth_m[p] = static_cast<float>(kFocus);
        rgb[0] = 200, rgb[1] = 500 + 400 * ((x / 2) % 2), rgb[2] = 300;
      } else {  // a textured background, far behind
        rgb[0] = 100 + 300 * (((x / 5) + (y / 5)) % 2), rgb[1] = 600, rgb[2] = 800;
      }
    }
  }
  std::vector<float> per_group, per_tile;
  std::int64_t narrowed = -1, not_narrowed = -1;
  apply_depth_of_field(camera, kFocus, frame.intrinsics(), frame.rgb, frame.depth_m, per_group,
                       {true, &narrowed});
  apply_depth_of_field(camera, kFocus, frame.intrinsics(), frame.rgb, frame.depth_m, per_tile,
                       {false, &not_narrowed});
  EXPECT_GT(narrowed, 500);
  EXPECT_EQ(not_narrowed, 0);
  ASSERT_EQ(per_group.size(), per_tile.size());
  std::size_t differing = 0;
  for (std::size_t i = 0; i < per_group.size(); ++i) differing += per_group[i] != per_tile[i];
  EXPECT_EQ(differing, 0u);
}

// A small camera with the 6D's 6.54 µm pixels, so diffraction has its real size in pixels.
ir::Camera small_sensor_camera(double f_number) {
  ir::Camera camera = canon_6d();
  camera.width_px = 240;
  camera.height_px = 160;
  camera.sensor_width_m = 240 * 0.0358 / 5472;
  camera.sensor_height_m = 160 * 0.0358 / 5472;
  camera.fx = camera.fy = camera.focal_length_m * 5472 / 0.0358;
  camera.cx = 120;
  camera.cy = 80;
  camera.aperture_f_number = f_number;
  camera.effects.diffraction = true;
  return camera;
}

double diffraction_edge_width(const ir::Camera& camera) {
  LinearFrame frame = flat_frame(sensor_intrinsics(camera, 1.0), 100, 1.0f);
  for (int y = 0; y < frame.height; ++y) {
    for (int x = frame.width / 2; x < frame.width; ++x) {
      for (int c = 0; c < 3; ++c)
        frame.rgb[3 * (static_cast<std::size_t>(y) * frame.width + x) + c] = 300;
    }
  }
  const DevelopResult r = develop_frame(camera, frame, {1, 0, 1}, 1.0);
  return width_10_90(row_profile(r, r.width / 2 - 20, r.width / 2 + 20));
}

TEST(DslrDiffraction, GaussianWidthFollowsTheFNumber) {
  // σ = 0.42·λ·N: 14.8 µm at f/64 = 2.26 px of 6.54 µm; a Gaussian edge is 2.563·σ wide (10-90 %).
  const double sigma_px = 0.42 * 550e-9 * 64 / (0.0358 / 5472);
  EXPECT_NEAR(diffraction_edge_width(small_sensor_camera(64)), 2.563 * sigma_px,
              0.1 * 2.563 * sigma_px);
  EXPECT_NEAR(diffraction_sigma_m(8), 1.848e-6, 1e-9);
  // At f/2.8 σ is 0.1 px: skipped, the edge stays a step.
  EXPECT_LT(diffraction_edge_width(small_sensor_camera(2.8)), 1.0);
}

// The blur is one pass, in place, over bands of rows with a ring of blurred rows and the rows
// around band borders kept; it must equal the plain separable Gaussian with clamped borders, on
// frames whose height is not a multiple of the bands (193: a last band of one row, under the
// wider kernels' reach) and whose width is under the kernel's reach at the edges. The f-numbers
// give every kernel radius from 1 to 4 (the loops unrolled for their tap counts) and wider ones
// (the generic loops).
TEST(DslrDiffraction, BandedPassEqualsTheSeparableGaussian) {
  std::set<int> radii;
  for (const double f_number : {8.0, 11.0, 16.0, 22.0, 27.0, 32.0, 45.0, 64.0}) {
    const ir::Camera camera = small_sensor_camera(f_number);
    Intrinsics canvas = sensor_intrinsics(camera, 1.0);
    for (const auto& [w, h] : {std::pair{37, 203}, std::pair{11, 193}, std::pair{9, 5}}) {
      canvas.width = w;
      canvas.height = h;
      std::vector<float> rgb(3 * static_cast<std::size_t>(w) * h);
      for (std::size_t i = 0; i < rgb.size(); ++i) {
        rgb[i] = static_cast<float>((i * 2654435761u) % 1000) / 10;
      }
      const std::vector<float> input = rgb;
      const double sigma = apply_diffraction(camera, canvas, rgb);
      ASSERT_GE(sigma, 0.2) << "f/" << f_number << " leaves the frame as it is";
      const int radius = diffraction_radius_px(sigma);
      radii.insert(radius);
      std::vector<double> kernel(2 * radius + 1);
      double total = 0;
      for (int k = -radius; k <= radius; ++k) {
        total += kernel[k + radius] = std::exp(-0.5 * k * k / (sigma * sigma));
      }
      double worst = 0;
      for (int y = 0; y < h; ++y) {
        for (int x = 0; x < w; ++x) {
          for (int c = 0; c < 3; ++c) {
            double expected = 0;
            for (int dy = -radius; dy <= radius; ++dy) {
              for (int dx = -radius; dx <= radius; ++dx) {
                const int xs = std::clamp(x + dx, 0, w - 1), ys = std::clamp(y + dy, 0, h - 1);
                expected += kernel[dx + radius] * kernel[dy + radius] *
                            input[3 * (static_cast<std::size_t>(ys) * w + xs) + c];
              }
            }
            expected /= total * total;
            worst = std::max(
                worst, std::abs(rgb[3 * (static_cast<std::size_t>(y) * w + x) + c] - expected));
          }
        }
      }
      EXPECT_LT(worst, 1e-3) << w << " x " << h << " at f/" << f_number;
    }
  }
  for (int radius = 1; radius <= 4; ++radius) EXPECT_TRUE(radii.count(radius)) << radius;
  EXPECT_GT(*radii.rbegin(), 4);
}

}  // namespace
}  // namespace rigc::dslr
