#include "run/run_loop.h"

#include <gtest/gtest.h>

#include <string>

#include "run/backend.h"

namespace rigc::run {
namespace {

TEST(RenderSamples, AreACountOrAuto) {
  EXPECT_EQ(parse_samples("auto"), kConvergedSamples);
  EXPECT_EQ(parse_samples("0"), 0);
  EXPECT_EQ(parse_samples("65536"), 65536);
  for (const std::string bad : {"", "-1", "65537", "1.5", "16x", "Auto", " 4"}) {
    EXPECT_FALSE(parse_samples(bad)) << bad;
  }
  EXPECT_EQ(samples_text(kConvergedSamples), "auto");
  EXPECT_EQ(samples_text(64), "64");
  EXPECT_EQ(parse_samples(samples_text(kConvergedSamples)), kConvergedSamples);
}

TEST(RenderSamples, NegativeCountsOtherThanAutoAreRefused) {
  RenderSettings settings;
  std::string error;
  settings.samples = kConvergedSamples;
  EXPECT_TRUE(settings.check(&error)) << error;
  settings.samples = -2;
  EXPECT_FALSE(settings.check(&error));
  EXPECT_EQ(error, "the samples per pixel must not be negative");
}

}  // namespace
}  // namespace rigc::run
