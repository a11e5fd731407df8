#include "compiler/scene_text.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

using ::testing::HasSubstr;

namespace rigc {
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

TEST(SceneText, ReplacesAScalarInAFlowMapAndKeepsTheRest) {
  std::string error;
  const std::string text =
      edited(set_value(kText, {"camera", "exposure", "aperture"}, "f/8", &error), error);
  EXPECT_THAT(text, HasSubstr("exposure: {aperture: f/8, shutter: 1/125, iso: 200}"));
  std::string expected = kText;
  expected.replace(expected.find("f/13"), 4, "f/8");
  EXPECT_EQ(text, expected);
}

TEST(SceneText, ReplacesABlockScalarAndKeepsItsComment) {
  std::string error;
  const std::string text =
      edited(set_value(kText, {"camera", "body"}, "nikon-d850", &error), error);
  EXPECT_THAT(text, HasSubstr("  body: nikon-d850   # the body\n"));
}

TEST(SceneText, ReplacesAFlowListAndAddsMissingKeys) {
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

TEST(SceneText, AppendsAndRemovesListItems) {
  std::string error;
  std::string text = edited(
      append_to_list(kText, {"shots"}, "pose: {position: [1, 0, 1], look_at: object}", &error),
      error);
  EXPECT_THAT(
      text, HasSubstr("step: 20deg}\n  - pose: {position: [1, 0, 1], look_at: object}\n# the end"));
  text = edited(remove_from_list(text, {"studio", "lights"}, 0, &error), error);
  EXPECT_THAT(text, HasSubstr("    # left\n    - {type: point"));
}

TEST(SceneText, RefusesTextThatCouldInjectStructure) {
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

TEST(SceneText, ReportsPathsThatDoNotFit) {
  std::string error;
  EXPECT_FALSE(set_value(kText, {"studio", "lights", "7", "power"}, "1W", &error).has_value());
  EXPECT_FALSE(error.empty());
  EXPECT_FALSE(set_value("a: [", {"a"}, "1", &error).has_value());
  EXPECT_FALSE(set_value(kText, {"camera", "body", "x"}, "1", &error).has_value());
}

const char* const kSections = R"(# a scene
rigc: 1   # version
name: s
shots:   # the old shots
  - turntable: {steps: 18, camera: {distance: 90cm}}
  # an old shot left commented out
  - pose: {position: [1m, 0, 1m]}

# the thresholds
coverage: {min_overlap: 0.5}
)";

TEST(SceneText, ReplacesOnlyTheShotsSection) {
  std::string error;
  const auto text =
      replace_section(kSections, "shots", "shots:\n  - pose: {position: [2m, 0, 1m]}\n", &error);
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

TEST(SceneText, ReplacesALastSectionToTheEnd) {
  std::string error;
  const auto text = replace_section("rigc: 1\nshots:\n  - pose: {position: [1m, 0, 1m]}\n  # end\n",
                                    "shots", "shots:\n  - x\n", &error);
  ASSERT_TRUE(text) << error;
  EXPECT_EQ(*text, "rigc: 1\nshots:\n  - x\n");
}

TEST(SceneText, RefusesTextWithoutABlockShotsKey) {
  std::string error;
  EXPECT_FALSE(replace_section("rigc: 1\nname: s\n", "shots", "shots:\n", &error));
  EXPECT_THAT(error, HasSubstr("shots"));
  EXPECT_FALSE(replace_section("{rigc: 1, shots: []}\n", "shots", "shots:\n", &error));
  EXPECT_FALSE(replace_section("rigc: [1\n", "shots", "shots:\n", &error));
}

TEST(SceneText, AppendsEntriesIndentedAsTheListIs) {
  std::string error;
  const auto text = append_to_section(
      "rigc: 1\nshots:\n- pose: {position: [1m, 0, 1m]}\n# trailing\n\ncoverage: {}\n", "shots",
      "  # added\n  - pose: {position: [2m, 0, 1m]}\n", &error);
  ASSERT_TRUE(text) << error;
  EXPECT_EQ(*text,
            "rigc: 1\nshots:\n- pose: {position: [1m, 0, 1m]}\n# added\n- pose: {position: [2m, "
            "0, 1m]}\n# trailing\n\ncoverage: {}\n");
}

TEST(SceneText, PathsFollowTheSchemasNames) {
  std::string error;
  const auto path = parse_scene_path("shots[0].turntable.steps", &error);
  ASSERT_TRUE(path) << error;
  EXPECT_EQ(*path, (ScenePath{"shots", "0", "turntable", "steps"}));
  EXPECT_FALSE(parse_scene_path("shots[x].a", &error));
  EXPECT_FALSE(parse_scene_path("[0].a", &error));
  EXPECT_FALSE(parse_scene_path("a..b", &error));
  EXPECT_FALSE(parse_scene_path("a;rm -rf", &error));
}

TEST(SceneText, ReplacesOnlyTheValuesSpanInFlowAndBlockStyle) {
  const std::string text =
      "camera:\n  exposure: {aperture: f/13, shutter: 1/125}  # keep\n  focus: auto # note\n"
      "shots:\n  - turntable: {steps: 18, step: 20deg}\n";
  std::string error;
  const auto span = find_value_span(text, {"camera", "exposure", "aperture"}, &error);
  ASSERT_TRUE(span) << error;
  EXPECT_EQ(span->line, 2);
  EXPECT_EQ(text.substr(span->begin, span->end - span->begin), "f/13");
  const auto edited = replace_values(text,
                                     {{{"camera", "exposure", "aperture"}, "f/4"},
                                      {{"shots", "0", "turntable", "steps"}, "36"},
                                      {{"camera", "focus"}, "1.2m"}},
                                     &error);
  ASSERT_TRUE(edited) << error;
  EXPECT_EQ(*edited,
            "camera:\n  exposure: {aperture: f/4, shutter: 1/125}  # keep\n  focus: 1.2m # note\n"
            "shots:\n  - turntable: {steps: 36, step: 20deg}\n");
  EXPECT_FALSE(find_value_span(text, {"camera", "exposure", "iso"}, &error));
  EXPECT_THAT(error, HasSubstr("'camera.exposure' has no key 'iso'"));
  EXPECT_FALSE(find_value_span(text, {"shots", "3", "turntable"}, &error));
  EXPECT_THAT(error, HasSubstr("'shots' has 1 items, no [3]"));
  const auto flow = find_value_span(text, {"camera", "exposure"}, &error);
  ASSERT_TRUE(flow) << error;
  EXPECT_FALSE(flow->scalar);
  EXPECT_EQ(text.substr(flow->begin, flow->end - flow->begin), "{aperture: f/13, shutter: 1/125}");
  EXPECT_FALSE(
      replace_values(text, {{{"camera", "focus"}, "1m"}, {{"camera", "focus"}, "2m"}}, &error));
  EXPECT_THAT(error, HasSubstr("the same value"));
}

TEST(SceneText, ValuesThatAreNotPlainAreQuoted) {
  EXPECT_EQ(yaml_scalar_text("f/8"), "f/8");
  EXPECT_EQ(yaml_scalar_text("-0.5"), "-0.5");
  EXPECT_EQ(yaml_scalar_text("a: b"), "\"a: b\"");
  EXPECT_EQ(yaml_scalar_text("x\"\n"), "\"x\\\"\\x0a\"");
  EXPECT_EQ(yaml_scalar_text("[1, 2]"), "\"[1, 2]\"");
}

}  // namespace
}  // namespace rigc
