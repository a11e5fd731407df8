#include "studio/scene_edit.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

using ::testing::HasSubstr;

namespace rigc::studio {
namespace {

const std::string kText =
    "# a comment at the top\n"
    "camera:\n"
    "  body: canon-6d   # the body\n"
    "  exposure: {aperture: f/13, shutter: 1/125, iso: 200}\n"
    "  focus: auto\n"
    "studio:\n"
    "  lights:\n"
    "    # left\n"
    "    - {type: area, position: [0.7m, -1.3m, 1.3m], power: 80W}\n"
    "    - {type: point, position: [-1m, -1m, 1.4m], power: 100W}\n"
    "shots:\n"
    "  - turntable: {steps: 18, step: 20deg}\n"
    "# the end\n";

std::string edited(const std::optional<std::string>& text, const std::string& error) {
  EXPECT_TRUE(text.has_value()) << error;
  return text.value_or("");
}

TEST(StudioSceneEdit, ReplacesAScalarInAFlowMapAndKeepsTheRest) {
  std::string error;
  const std::string text =
      edited(set_value(kText, {"camera", "exposure", "aperture"}, "f/8", &error), error);
  EXPECT_THAT(text, HasSubstr("exposure: {aperture: f/8, shutter: 1/125, iso: 200}"));
  std::string expected = kText;
  expected.replace(expected.find("f/13"), 4, "f/8");
  EXPECT_EQ(text, expected);
}

TEST(StudioSceneEdit, ReplacesABlockScalarAndKeepsItsComment) {
  std::string error;
  const std::string text =
      edited(set_value(kText, {"camera", "body"}, "nikon-d850", &error), error);
  EXPECT_THAT(text, HasSubstr("  body: nikon-d850   # the body\n"));
}

TEST(StudioSceneEdit, ReplacesAFlowListAndAddsMissingKeys) {
  std::string error;
  std::string text = edited(
      set_value(kText, {"studio", "lights", "1", "position"}, "[0, -2m, 1m]", &error), error);
  EXPECT_THAT(text, HasSubstr("{type: point, position: [0, -2m, 1m], power: 100W}"));
  text = edited(set_value(text, {"studio", "lights", "1", "temperature"}, "3200K", &error), error);
  EXPECT_THAT(text, HasSubstr("power: 100W, temperature: 3200K}"));
  text = edited(set_value(text, {"camera", "white_balance"}, "5600K", &error), error);
  EXPECT_THAT(text, HasSubstr("  focus: auto\n  white_balance: 5600K\nstudio:"));
  text = edited(set_value(text, {"studio", "turntable", "diameter"}, "50cm", &error), error);
  EXPECT_THAT(text, HasSubstr("studio:\n  lights:"));
  EXPECT_THAT(text,
              HasSubstr("power: 100W, temperature: 3200K}\n  turntable: {diameter: 50cm}\nshots:"));
}

TEST(StudioSceneEdit, AppendsAndRemovesListItems) {
  std::string error;
  std::string text = edited(
      append_to_list(kText, {"shots"}, "pose: {position: [1, 0, 1], look_at: object}", &error),
      error);
  EXPECT_THAT(
      text, HasSubstr("step: 20deg}\n  - pose: {position: [1, 0, 1], look_at: object}\n# the end"));
  text = edited(remove_from_list(text, {"studio", "lights"}, 0, &error), error);
  EXPECT_THAT(text, HasSubstr("    # left\n    - {type: point"));
}

TEST(StudioSceneEdit, RefusesTextThatCouldInjectStructure) {
  for (const char* value : {"f/8}\nobject: {mesh: /etc/passwd}", "a: b", "x # y", "{a}", "",
                            "- item", "[[1]]", "'q'"}) {
    EXPECT_FALSE(is_safe_value_text(value)) << value;
    std::string error;
    EXPECT_FALSE(set_value(kText, {"camera", "body"}, value, &error).has_value());
  }
  for (const char* value : {"f/8", "1/125", "-1.3m", "[0.7m, -1.3m, 1.3m]", "auto", "5600K"}) {
    EXPECT_TRUE(is_safe_value_text(value)) << value;
  }
}

TEST(StudioSceneEdit, ReportsPathsThatDoNotFit) {
  std::string error;
  EXPECT_FALSE(set_value(kText, {"studio", "lights", "7", "power"}, "1W", &error).has_value());
  EXPECT_FALSE(error.empty());
  EXPECT_FALSE(set_value("a: [", {"a"}, "1", &error).has_value());
  EXPECT_FALSE(set_value(kText, {"camera", "body", "x"}, "1", &error).has_value());
}

}  // namespace
}  // namespace rigc::studio
