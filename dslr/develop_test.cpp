#include "dslr/develop.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "dslr/dslr_test_support.h"
#include "dslr/exposure.h"
#include "dslr/pipeline.h"

using ::testing::HasSubstr;

namespace rigc::dslr {
namespace {

using testing::canon_6d;
using testing::flat_frame;

double luminance(const ir::Vec3& c) {
  return 0.2126 * c.x() + 0.7152 * c.y() + 0.0722 * c.z();
}

TEST(DslrDevelop, BlackbodyIsNormalisedToLuminanceOne) {
  for (double k : {2000.0, 3200.0, 5600.0, 6504.0, 10000.0}) {
    EXPECT_NEAR(luminance(blackbody_rgb(k)), 1, 1e-9) << k;
  }
  const ir::Vec3 tungsten = blackbody_rgb(3200), daylight = blackbody_rgb(6504),
                 sky = blackbody_rgb(10000);
  EXPECT_GT(tungsten.x(), tungsten.y());
  EXPECT_GT(tungsten.y(), tungsten.z());
  EXPECT_GT(sky.z(), sky.x());
  // D65 is close to, but not on, the Planckian locus.
  EXPECT_NEAR(daylight.x(), 1, 0.05);
  EXPECT_NEAR(daylight.z(), 1, 0.1);
}

TEST(DslrDevelop, SrgbEncodingOfMidGrey) {
  EXPECT_NEAR(srgb_oetf(0.18), 0.4614, 1e-4);
  EXPECT_NEAR(srgb_oetf(0.002), 12.92 * 0.002, 1e-12);
  const std::vector<float> linear{0.18f, 0.0f, 1.0f, 2.0f, -0.1f, 0.5f};
  const auto eight = encode_srgb(linear, {1, 1, 1}, 8);
  EXPECT_EQ(eight, (std::vector<std::uint16_t>{118, 0, 255, 255, 0, 188}));
  const auto sixteen = encode_srgb(linear, {1, 1, 1}, 16);
  EXPECT_NEAR(sixteen[0], 0.4614 * 65535, 8);
  EXPECT_EQ(sixteen[2], 65535);
}

// A white surface lit by a blackbody of `kelvin`, developed with the camera's white balance.
DevelopResult white_under(const ir::Camera& camera, double kelvin, bool mask_green_background) {
  const double scale = 0.05;
  LinearFrame frame = flat_frame(sensor_intrinsics(camera, scale), 0, 1.0f);
  const ir::Vec3 light = blackbody_rgb(kelvin);
  frame.mask.assign(static_cast<std::size_t>(frame.width) * frame.height, 0);
  for (int y = 0; y < frame.height; ++y) {
    for (int x = 0; x < frame.width; ++x) {
      const std::size_t p = static_cast<std::size_t>(y) * frame.width + x;
      const bool object = x < frame.width / 2;
      const ir::Vec3 albedo = object ? ir::Vec3(0.8, 0.8, 0.8) : ir::Vec3(0.0, 0.69, 0.25);
      frame.mask[p] = object ? 255 : 0;
      for (int c = 0; c < 3; ++c)
        frame.rgb[3 * p + c] = static_cast<float>(800 * albedo[c] * light[c]);
    }
  }
  if (!mask_green_background) frame.mask.clear();
  return develop_frame(camera, frame, {1, 0, 1}, scale);
}

void expect_neutral_object(const DevelopResult& r) {
  const std::size_t p = 3 * (static_cast<std::size_t>(r.height / 2) * r.width + r.width / 4);
  EXPECT_NEAR(r.encoded[p], r.encoded[p + 1], 1);
  EXPECT_NEAR(r.encoded[p + 2], r.encoded[p + 1], 1);
}

TEST(DslrDevelop, KelvinWhiteBalanceNeutralisesThatLight) {
  ir::Camera camera = canon_6d();
  camera.white_balance = ir::WhiteBalanceMode::kKelvin;
  camera.white_balance_k = 3200;
  const DevelopResult r = white_under(camera, 3200, false);
  expect_neutral_object(r);
  // The linear output is before white balance: still tungsten-coloured.
  const std::size_t p = 3 * (static_cast<std::size_t>(r.height / 2) * r.width + r.width / 4);
  EXPECT_GT(r.linear[p], 1.5 * r.linear[p + 2]);
  // The wrong white balance leaves a cast.
  camera.white_balance_k = 6500;
  const DevelopResult wrong = white_under(camera, 3200, false);
  EXPECT_GT(wrong.encoded[p], wrong.encoded[p + 2] + 20);
}

TEST(DslrDevelop, AutoWhiteBalanceUsesTheObjectMask) {
  ir::Camera camera = canon_6d();
  camera.white_balance = ir::WhiteBalanceMode::kAuto;
  expect_neutral_object(white_under(camera, 3200, true));
  // Without the mask the green screen pulls the grey world towards magenta.
  const DevelopResult unmasked = white_under(camera, 3200, false);
  const std::size_t p =
      3 * (static_cast<std::size_t>(unmasked.height / 2) * unmasked.width + unmasked.width / 4);
  EXPECT_GT(unmasked.encoded[p] + unmasked.encoded[p + 2], 2 * unmasked.encoded[p + 1] + 20);
}

TEST(DslrDevelop, OutputBitsFollowTheFormat) {
  ir::Camera camera = canon_6d();
  EXPECT_EQ(output_bits(camera), 8);
  camera.format = ir::ImageFormat::kPng16;
  EXPECT_EQ(output_bits(camera), 16);
  const DevelopResult r = white_under(camera, 6504, false);
  EXPECT_EQ(r.bits, 16);
  std::uint16_t top = 0;
  for (std::uint16_t v : r.encoded) top = std::max(top, v);
  EXPECT_GT(top, 255);
}

TEST(DslrDevelop, MalformedFrameIsAnError) {
  const ir::Camera camera = canon_6d();
  LinearFrame frame = flat_frame(sensor_intrinsics(camera, 0.05), 100, 1.0f);
  frame.depth_m.pop_back();
  std::string error;
  const DevelopResult r = develop_frame(camera, frame, {}, 0.05, &error);
  EXPECT_TRUE(r.encoded.empty());
  EXPECT_THAT(error, HasSubstr("depth"));
}

}  // namespace
}  // namespace rigc::dslr
