#include "plan/scene_text.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

using ::testing::HasSubstr;

namespace rigc::plan {
namespace {

const char* const kScene = R"(# a scene
rigc: 1   # version
name: s
shots:   # the old shots
  - turntable: {steps: 18, camera: {distance: 90cm}}
  # an old shot left commented out
  - pose: {position: [1m, 0, 1m]}

# the thresholds
coverage: {min_overlap: 0.5}
)";

TEST(PlanSceneText, ReplacesOnlyTheShotsSection) {
  std::string error;
  const auto text =
      replace_shots_section(kScene, "shots:\n  - pose: {position: [2m, 0, 1m]}\n", &error);
  ASSERT_TRUE(text) << error;
  EXPECT_EQ(*text, R"(# a scene
rigc: 1   # version
name: s
shots:
  - pose: {position: [2m, 0, 1m]}

# the thresholds
coverage: {min_overlap: 0.5}
)");
}

TEST(PlanSceneText, ReplacesALastSectionToTheEnd) {
  std::string error;
  const auto text = replace_shots_section(
      "rigc: 1\nshots:\n  - pose: {position: [1m, 0, 1m]}\n  # end\n", "shots:\n  - x\n", &error);
  ASSERT_TRUE(text) << error;
  EXPECT_EQ(*text, "rigc: 1\nshots:\n  - x\n");
}

TEST(PlanSceneText, RefusesTextWithoutABlockShotsKey) {
  std::string error;
  EXPECT_FALSE(replace_shots_section("rigc: 1\nname: s\n", "shots:\n", &error));
  EXPECT_THAT(error, HasSubstr("shots"));
  EXPECT_FALSE(replace_shots_section("{rigc: 1, shots: []}\n", "shots:\n", &error));
  EXPECT_FALSE(replace_shots_section("rigc: [1\n", "shots:\n", &error));
}

TEST(PlanSceneText, AppendsEntriesIndentedAsTheListIs) {
  std::string error;
  const auto text = append_to_shots_section(
      "rigc: 1\nshots:\n- pose: {position: [1m, 0, 1m]}\n# trailing\n\ncoverage: {}\n",
      "  # added\n  - pose: {position: [2m, 0, 1m]}\n", &error);
  ASSERT_TRUE(text) << error;
  EXPECT_EQ(*text,
            "rigc: 1\nshots:\n- pose: {position: [1m, 0, 1m]}\n# added\n- pose: {position: [2m, "
            "0, 1m]}\n# trailing\n\ncoverage: {}\n");
}

}  // namespace
}  // namespace rigc::plan
