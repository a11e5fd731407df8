#include "eval/photo_diagnosis.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <random>

using ::testing::HasSubstr;

namespace rigc::eval {
namespace {

KeyImage noise_picture(int scale_of_blocks, double gain) {
  KeyImage im;
  im.width = im.height = 64;
  im.srgb.resize(im.pixels() * 3);
  std::mt19937 random(5);
  std::vector<std::uint8_t> block(64 * 64);
  for (auto& v : block) v = static_cast<std::uint8_t>(random() % 200 + 30);
  for (int y = 0; y < 64; ++y) {
    for (int x = 0; x < 64; ++x) {
      const int bx = x / scale_of_blocks * scale_of_blocks,
                by = y / scale_of_blocks * scale_of_blocks;
      const auto v = static_cast<std::uint8_t>(block[by * 64 + bx] * gain);
      for (int c = 0; c < 3; ++c) im.srgb[3 * (y * 64 + x) + c] = v;
    }
  }
  return im;
}

TEST(PhotoDiagnosis, StatisticsSeeBlurAndDarkness) {
  const auto sharp = image_statistics(noise_picture(1, 1.0), {});
  const auto soft = image_statistics(noise_picture(8, 1.0), {});
  const auto dark = image_statistics(noise_picture(1, 0.1), {});
  EXPECT_GT(sharp.sharpness, 10 * soft.sharpness);
  EXPECT_LT(dark.mean_luma, 0.2 * sharp.mean_luma);
  EXPECT_LT(dark.p99_luma, 0.25);
  // Over a mask: only its pixels count.
  std::vector<std::uint8_t> mask(64 * 64, 0);
  mask[10 * 64 + 10] = 255;
  const auto one = image_statistics(noise_picture(1, 1.0), mask);
  EXPECT_NEAR(one.mean_luma, one.p99_luma, 1e-9);
}

TEST(PhotoDiagnosis, EachUnregisteredImageGetsItsCauses) {
  DiagnosisInputs in;
  for (int i = 0; i < 8; ++i) {
    const std::string name = "p" + std::to_string(i);
    in.order.push_back(name);
    in.stats[name] = {100, 0.4, 0.8};
    in.features[name] = 1000;
    if (i != 2 && i != 5 && i != 6) in.registered.insert(name);
  }
  in.stats["p2"] = {5, 0.05, 0.1};  // dark (and so little contrast)
  in.stats["p5"] = {10, 0.4, 0.8};  // blurred
  in.features["p5"] = 100;
  in.masked = false;
  in.still_fraction = 0.6;
  const auto causes = diagnose_unregistered(in);
  ASSERT_EQ(causes.size(), 3u);
  auto has = [&](const std::string& name, const std::string& word) {
    for (const auto& c : causes.at(name)) {
      if (c.find(word) != std::string::npos) return true;
    }
    return false;
  };
  EXPECT_TRUE(has("p2", "under-exposed"));
  EXPECT_FALSE(has("p2", "blurred"));
  EXPECT_TRUE(has("p5", "blurred"));
  EXPECT_TRUE(has("p5", "few features"));
  EXPECT_TRUE(has("p6", "static background"));
  EXPECT_FALSE(has("p6", "overlap")) << "p6 has a visible cause and a registered neighbour";
  // With masks, p6 shows no cause in its statistics: its neighbours did not overlap it.
  in.masked = true;
  const auto masked = diagnose_unregistered(in);
  ASSERT_EQ(masked.at("p6").size(), 1u);
  EXPECT_THAT(masked.at("p6")[0], HasSubstr("overlap"));
  EXPECT_EQ(masked.at("p2").size(), 1u) << "dark only";
}

TEST(PhotoDiagnosis, FeaturesAreReadFromTheExtractorLog) {
  const auto f = features_by_image(
      "Processed file [1/2]\n  Name:            shot 0.jpg\n  Dimensions:      821 x 547\n"
      "  Features:        2328\nProcessed file [2/2]\n  Name:            b.jpg\n"
      "  Features:        12\n");
  ASSERT_EQ(f.size(), 2u);
  EXPECT_EQ(f.at("shot 0.jpg"), 2328);
  EXPECT_EQ(f.at("b.jpg"), 12);
}

}  // namespace
}  // namespace rigc::eval
