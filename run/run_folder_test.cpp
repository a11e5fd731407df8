#include "run/run_folder.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

namespace rigc::run {
namespace {

using ::testing::HasSubstr;
using ::testing::Not;

TEST(RunProgress, TheTimeLeftReadsAsAPersonSaysIt) {
  EXPECT_EQ(time_left_text(0.4), "0 s");
  EXPECT_EQ(time_left_text(42.6), "43 s");
  EXPECT_EQ(time_left_text(130), "2 min 10 s");
  EXPECT_EQ(time_left_text(3900), "1 h 5 min");
  EXPECT_EQ(time_left_text(-3), "0 s");
}

TEST(RunProgress, TheBarSaysTheTimeLeftUntilTheLastShot) {
  const std::string fifth = progress_line(5, 18, "shot_004", 0.42, 6.2);
  EXPECT_THAT(fifth, HasSubstr("] 5/18 shot_004 0.42 s, about 6 s left"));
  EXPECT_EQ(fifth.front(), '\r');
  EXPECT_THAT(progress_line(18, 18, "shot_017", 0.4, 0), Not(HasSubstr("left")));
}

}  // namespace
}  // namespace rigc::run
