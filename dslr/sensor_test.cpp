#include "dslr/sensor.h"

#include <gtest/gtest.h>
#include <tbb/task_arena.h>

#include <cmath>

#include "dslr/develop.h"
#include "dslr/dslr_test_support.h"
#include "dslr/exposure.h"
#include "dslr/pipeline.h"

namespace rigc::dslr {
namespace {

using testing::canon_6d;
using testing::flat_frame;

constexpr double kScale = 0.05;  // 274 x 182 pixels: 150k samples per patch

struct Stats {
  double mean = 0, std = 0;
};

Stats stats(const std::vector<float>& v, double to_electrons) {
  double sum = 0, sum2 = 0;
  for (float x : v) sum += x * to_electrons;
  const double mean = sum / v.size();
  for (float x : v) sum2 += (x * to_electrons - mean) * (x * to_electrons - mean);
  return {mean, std::sqrt(sum2 / (v.size() - 1))};
}

// A flat patch exposed to the normalised signal v, developed with noise on.
DevelopResult flat_patch(const ir::Camera& camera, double v, std::uint64_t seed = 7, int shot = 0) {
  const float luminance = static_cast<float>(v / exposure_scale(camera));
  return develop_frame(camera, flat_frame(sensor_intrinsics(camera, kScale), luminance, 1.0f),
                       {1, shot, seed}, kScale);
}

ir::Camera noisy_6d(double iso) {
  ir::Camera camera = canon_6d();
  camera.effects.noise = true;
  camera.iso = iso;
  return camera;
}

// The fused pass of a run that keeps only the encoded image gives the codes of the two stages
// run one after the other: noise on and off, at 8 and 16 bits, with a value count that ends in a
// partial group of eight, and through develop_frame.
TEST(DslrNoise, SensorAndEncodingInOnePassGiveTheSameCodes) {
  ir::Camera camera = canon_6d();
  const int width = 101, height = 7;  // 2121 values: not a multiple of eight
  std::vector<float> signal(3 * width * height);
  for (std::size_t i = 0; i < signal.size(); ++i) {
    signal[i] = static_cast<float>((i * 2654435761u) % 1200) / 1000 - 0.05f;  // past both ends
  }
  const std::array<double, 3> gains = {2.1, 1.0, 1.4};
  for (const bool noise : {true, false}) {
    for (const int bits : {8, 16}) {
      camera.effects.noise = noise;
      std::vector<float> two_stages = signal;
      apply_sensor(camera, view_of(two_stages, width, height), {5, 3});
      const std::vector<std::uint16_t> expected = encode_srgb(two_stages, gains, bits);
      const std::vector<float> before = signal;
      const std::vector<std::uint16_t> fused = apply_sensor_and_encode(
          camera, view_of(signal, width, height), {5, 3}, srgb_encoding(gains, bits));
      EXPECT_EQ(fused, expected) << "noise " << noise << ", " << bits << " bits";
      EXPECT_EQ(signal, before);
      if (bits == 8) {
        const std::vector<std::uint8_t> bytes = apply_sensor_and_encode_bytes(
            camera, view_of(signal, width, height), {5, 3}, srgb_encoding(gains, bits));
        EXPECT_EQ(std::vector<std::uint16_t>(bytes.begin(), bytes.end()), expected);
      }
    }
  }
  camera.effects.noise = true;
  camera.white_balance = ir::WhiteBalanceMode::kKelvin;  // gains fixed before the image exists
  camera.white_balance_k = 4300;
  const LinearFrame frame = flat_frame(sensor_intrinsics(camera, 0.05), 400.0, 1.0f);
  ShotParams kept, dropped;
  dropped.keep_linear = false;
  const DevelopResult a = develop_frame(camera, frame, kept, 0.05);
  const DevelopResult b = develop_frame(camera, frame, dropped, 0.05);
  EXPECT_FALSE(a.linear.empty());
  EXPECT_TRUE(b.linear.empty());
  // 8 bits (the canon_6d preset writes JPEG): the codes come as bytes.
  ASSERT_EQ(output_bits(camera), 8);
  EXPECT_TRUE(b.encoded.empty());
  EXPECT_EQ(std::vector<std::uint16_t>(b.encoded_bytes.begin(), b.encoded_bytes.end()), a.encoded);
  EXPECT_GT(a.encoded[0], 20);  // not black
}

TEST(DslrNoise, ReadNoiseIsInterpolatedInLogIso) {
  const ir::SensorNoise n = canon_6d().noise;
  EXPECT_NEAR(read_noise_electrons(n, 100), n.read_noise_e, 1e-9);
  EXPECT_NEAR(read_noise_electrons(n, 6400), n.read_noise_high_iso_e, 1e-9);
  EXPECT_NEAR(read_noise_electrons(n, 800), std::sqrt(n.read_noise_e * n.read_noise_high_iso_e),
              1e-9);
  EXPECT_NEAR(read_noise_electrons(n, 25600), n.read_noise_high_iso_e, 1e-9);
  EXPECT_NEAR(electrons_at_clipping(n, 6400), 79546.0 / 64, 1e-9);
}

// The standard deviation of a flat patch, in electrons, against the sum of the variances.
void expect_patch_noise(double iso) {
  const ir::Camera camera = noisy_6d(iso);
  const ir::SensorNoise& n = camera.noise;
  const double fwc = 79546.0 * 100 / iso;  // Canon 6D: electrons at clipping scale as 1/ISO
  const double v = 0.18;
  const double e = v * fwc + n.dark_current_e_per_s * camera.shutter_s;
  const double read = read_noise_electrons(n, iso);
  const double lsb = fwc / (std::pow(2.0, n.adc_bits) - 1);
  const double expected = std::sqrt(e                                // shot noise
                                    + std::pow(n.prnu * v * fwc, 2)  // pixel gain (fixed)
                                    + read * read + n.dsnu_e * n.dsnu_e + lsb * lsb / 12);
  const Stats s = stats(flat_patch(camera, v).linear, fwc);
  EXPECT_NEAR(s.mean, e, 0.01 * e) << "ISO " << iso;
  EXPECT_NEAR(s.std, expected, 0.1 * expected) << "ISO " << iso;
}

TEST(DslrNoise, FlatPatchStdMatchesTheNoiseBudget) {
  expect_patch_noise(100);   // ~158 e: shot 120, PRNU 100, read 25
  expect_patch_noise(6400);  // ~15 e: shot dominates, read 1.7
  expect_patch_noise(800);
}

TEST(DslrNoise, DarkFrameKeepsAnUnbiasedMean) {
  // Negative excursions are kept (the ADC's black level), so the dark mean is not pushed up.
  const ir::Camera camera = noisy_6d(6400);
  const double fwc = 79546.0 / 64;
  const Stats s = stats(flat_patch(camera, 0).linear, fwc);
  const double read = read_noise_electrons(camera.noise, 6400);
  EXPECT_NEAR(s.mean, camera.noise.dark_current_e_per_s * camera.shutter_s, 0.05);
  EXPECT_NEAR(s.std, std::hypot(read, camera.noise.dsnu_e), 0.1 * std::hypot(read, 1.0));
}

// ISO 6400 with the fixed pattern off and a negligible read noise: the shot noise alone.
ir::Camera shot_noise_only_6d() {
  ir::Camera camera = noisy_6d(6400);
  camera.noise.read_noise_high_iso_e = 0.01;
  camera.noise.prnu = 0;
  camera.noise.dsnu_e = 0;
  return camera;
}

TEST(DslrNoise, SmallSignalsArePoisson) {
  // 5 electrons mean: exact Poisson draws, variance = mean (plus a tiny read noise).
  const ir::Camera camera = shot_noise_only_6d();
  const double fwc = 79546.0 / 64;
  const Stats s = stats(flat_patch(camera, 5 / fwc).linear, fwc);
  const std::vector<float> linear = flat_patch(camera, 5 / fwc).linear;
  EXPECT_NEAR(s.mean, 5, 0.05);
  EXPECT_NEAR(s.std * s.std, 5, 0.25);
  // P(0) = e^-5 = 0.67 %; a Gaussian of the same variance would put 2.2 % below 0.5 e.
  std::size_t zeros = 0;
  for (float v : linear) zeros += v * fwc < 0.5;
  EXPECT_NEAR(static_cast<double>(zeros) / linear.size(), std::exp(-5.0), 0.002);
}

// Small signals under base-ISO read noise (about 16 e⁻ at ISO 200): the sum's mean and
// variance must be the Poisson law's plus the read noise's, with nothing held at zero.
TEST(DslrNoise, SmallSignalsUnderReadNoiseKeepTheirMeanAndVariance) {
  ir::Camera camera = noisy_6d(200);
  camera.noise.prnu = 0;
  camera.noise.dsnu_e = 0;
  const double read = read_noise_electrons(camera.noise, 200);
  ASSERT_GT(read, 10);
  const double fwc = 79546.0 / 2;
  const double dark = camera.noise.dark_current_e_per_s * camera.shutter_s;
  for (const double electrons : {0.3, 3.0, 9.0}) {
    const std::vector<float> linear = flat_patch(camera, electrons / fwc).linear;
    const Stats s = stats(linear, fwc);
    const double lsb = fwc / (std::pow(2.0, camera.noise.adc_bits) - 1);
    const double variance = electrons + dark + read * read + lsb * lsb / 12;
    // The mean of n draws varies by sqrt(variance / n); the variance's by about 2 %.
    EXPECT_NEAR(s.mean, electrons + dark, 4 * std::sqrt(variance / linear.size())) << electrons;
    EXPECT_NEAR(s.std * s.std, variance, 0.03 * variance) << electrons;
  }
}

TEST(DslrNoise, ModerateSignalsKeepThePoissonSkew) {
  // 20 electrons: drawn from a skew-corrected Gaussian, whose variance and third moment must
  // still be the Poisson law's (mean 20, variance 20, skewness 1/sqrt(20) = 0.224).
  const ir::Camera camera = shot_noise_only_6d();
  const double fwc = 79546.0 / 64;
  const std::vector<float> linear = flat_patch(camera, 20 / fwc).linear;
  double sum = 0, sum2 = 0, sum3 = 0;
  for (float v : linear) sum += v * fwc;
  const double mean = sum / linear.size();
  for (float v : linear) {
    const double d = v * fwc - mean;
    sum2 += d * d;
    sum3 += d * d * d;
  }
  const double variance = sum2 / linear.size();
  const double skewness = sum3 / linear.size() / std::pow(variance, 1.5);
  EXPECT_NEAR(mean, 20, 0.1);
  // The ADC's steps (0.3 electrons here) add 1/12 of a step squared.
  EXPECT_NEAR(variance, 20, 0.6);
  EXPECT_NEAR(skewness, 1 / std::sqrt(20.0), 0.04);
}

TEST(DslrNoise, ClipsAtFullWell) {
  const DevelopResult r = flat_patch(noisy_6d(100), 3.0);
  for (float v : r.linear) ASSERT_EQ(v, 1.0f);
}

double correlation(const std::vector<float>& a, const std::vector<float>& b) {
  double ma = 0, mb = 0;
  for (std::size_t i = 0; i < a.size(); ++i) ma += a[i], mb += b[i];
  ma /= a.size(), mb /= b.size();
  double sab = 0, saa = 0, sbb = 0;
  for (std::size_t i = 0; i < a.size(); ++i) {
    sab += (a[i] - ma) * (b[i] - mb), saa += (a[i] - ma) * (a[i] - ma),
        sbb += (b[i] - mb) * (b[i] - mb);
  }
  return sab / std::sqrt(saa * sbb);
}

TEST(DslrNoise, FixedPatternIsTheSameInEveryShotOfOneCamera) {
  // At ISO 100 and v = 0.18 PRNU is 40 % of the variance: two shots correlate by that much.
  const ir::Camera camera = noisy_6d(100);
  const auto shot0 = flat_patch(camera, 0.18, 7, 0).linear;
  const auto shot1 = flat_patch(camera, 0.18, 7, 1).linear;
  const auto other_camera = flat_patch(camera, 0.18, 8, 1).linear;
  const double e = 0.18 * 79546, prnu = 0.007 * e;
  const double expected = prnu * prnu / (e + prnu * prnu + 25 * 25 + 1);
  EXPECT_NEAR(correlation(shot0, shot1), expected, 0.05);
  EXPECT_NEAR(correlation(shot0, other_camera), 0, 0.02);
}

TEST(DslrNoise, NoiseFreeModeOnlyClips) {
  ir::Camera camera = noisy_6d(100);
  camera.effects.noise = false;
  const DevelopResult r = flat_patch(camera, 0.18);
  for (float v : r.linear) ASSERT_NEAR(v, 0.18f, 1e-6);
}

TEST(DslrNoise, GaussianTableIsStandardNormal) {
  double sum = 0, sum2 = 0, sum4 = 0;
  for (std::uint32_t k = 0; k < 65536; ++k) {
    const double z = normal_from_bits(k);
    sum += z, sum2 += z * z, sum4 += z * z * z * z;
  }
  EXPECT_NEAR(sum / 65536, 0, 1e-6);
  EXPECT_NEAR(sum2 / 65536, 1, 2e-3);
  EXPECT_NEAR(sum4 / 65536, 3, 0.05);  // kurtosis of a normal
}

// A frame that exercises every stage: depth steps, texture, a mask.
LinearFrame busy_frame(const ir::Camera& camera, double scale) {
  LinearFrame frame = flat_frame(render_geometry_for(camera, scale), 0, 2.0f);
  frame.mask.assign(static_cast<std::size_t>(frame.width) * frame.height, 0);
  for (int y = 0; y < frame.height; ++y) {
    for (int x = 0; x < frame.width; ++x) {
      const std::size_t p = static_cast<std::size_t>(y) * frame.width + x;
      const bool object =
          std::hypot(x - frame.width / 2.0, y - frame.height / 2.0) < frame.height / 3.0;
      frame.depth_m[p] = object ? 0.8f + 0.001f * (x % 50) : 2.0f;
      frame.mask[p] = object ? 255 : 0;
      for (int c = 0; c < 3; ++c)
        frame.rgb[3 * p + c] = 200.0f + 600.0f * ((x / 7 + y / 5 + c) % 3);
    }
  }
  return frame;
}

ir::Camera every_effect() {
  ir::Camera camera = canon_6d();
  camera.effects = {true, true, true, true, true, true};
  camera.distortion.k1 = -0.08;
  camera.vignetting = 0.3;
  camera.aperture_f_number = 4;
  camera.white_balance = ir::WhiteBalanceMode::kAuto;
  return camera;
}

TEST(DslrDeterminism, SameSeedGivesIdenticalBytesWithAnyThreadCount) {
  const ir::Camera camera = every_effect();
  const double scale = 0.1;
  const LinearFrame frame = busy_frame(camera, scale);
  const ShotParams shot{0.8, 3, 42};
  const DevelopResult a = develop_frame(camera, frame, shot, scale);
  DevelopResult b;
  tbb::task_arena single(1);
  single.execute([&] { b = develop_frame(camera, frame, shot, scale); });
  ASSERT_FALSE(a.encoded.empty());
  EXPECT_EQ(a.encoded, b.encoded);
  EXPECT_EQ(a.linear, b.linear);
  EXPECT_EQ(a.mask, b.mask);

  const DevelopResult other_seed = develop_frame(camera, frame, {0.8, 3, 43}, scale);
  const DevelopResult other_shot = develop_frame(camera, frame, {0.8, 4, 42}, scale);
  EXPECT_NE(a.encoded, other_seed.encoded);
  EXPECT_NE(a.encoded, other_shot.encoded);
}

}  // namespace
}  // namespace rigc::dslr
