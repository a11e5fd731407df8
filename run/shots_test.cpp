#include "run/shots.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

using ::testing::HasSubstr;
using ::testing::Not;

namespace rigc::run {
namespace {

std::vector<int> parse_ok(const std::string& text, int count) {
  std::string error;
  auto selection = parse_shot_selection(text, count, &error);
  EXPECT_TRUE(selection.has_value()) << text << ": " << error;
  return selection.value_or(std::vector<int>{});
}

std::string parse_error(const std::string& text, int count) {
  std::string error;
  auto selection = parse_shot_selection(text, count, &error);
  EXPECT_FALSE(selection.has_value()) << text;
  EXPECT_THAT(error, Not(HasSubstr("\n")));
  return error;
}

TEST(BackendShots, ParsesIndicesAndRanges) {
  EXPECT_EQ(parse_ok("0,3,5-7", 10), (std::vector<int>{0, 3, 5, 6, 7}));
  EXPECT_EQ(parse_ok("7,5-6,0,6", 10), (std::vector<int>{0, 5, 6, 7}));  // sorted, unique
  EXPECT_EQ(parse_ok(" 2 , 4 - 5 ", 10), (std::vector<int>{2, 4, 5}));
  EXPECT_EQ(parse_ok("9", 10), (std::vector<int>{9}));
  EXPECT_EQ(parse_ok("3-3", 10), (std::vector<int>{3}));
}

TEST(BackendShots, AllSelectsEverythingAndEmptyIsAnError) {
  EXPECT_EQ(parse_ok("all", 3), (std::vector<int>{0, 1, 2}));
  EXPECT_EQ(parse_ok(" all ", 3), (std::vector<int>{0, 1, 2}));
  EXPECT_EQ(parse_ok("all", 0), (std::vector<int>{}));
  for (const char* text : {"", "  "}) {
    const std::string error = parse_error(text, 3);
    EXPECT_THAT(error, HasSubstr("empty"));
    EXPECT_THAT(error, HasSubstr("0..2"));
  }
}

TEST(BackendShots, ReportsErrorsWithTheValidRange) {
  for (const char* text : {"10", "5-10", "99999999999999999999999"}) {
    const std::string error = parse_error(text, 10);
    EXPECT_THAT(error, HasSubstr("out of range"));
    EXPECT_THAT(error, HasSubstr("0..9"));
  }
  const std::string reversed = parse_error("7-5", 10);
  EXPECT_THAT(reversed, HasSubstr("reversed"));
  EXPECT_THAT(reversed, HasSubstr("0..9"));
  for (const char* text : {"x", "1,,2", "1,", "-3", "3-", "1-2-3", "1.5", "0x3", "shot_001"}) {
    const std::string error = parse_error(text, 10);
    EXPECT_THAT(error, HasSubstr("0..9")) << text << ": " << error;
  }
  EXPECT_THAT(parse_error("0", 0), HasSubstr("no shots"));
}

}  // namespace
}  // namespace rigc::run
