#include "compiler/yaml_limits.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <chrono>
#include <string>

#include "compiler/frontend.h"
#include "tests/test_support.h"

using ::testing::HasSubstr;
using ::testing::Not;

namespace rigc {
namespace {

// Each extra alias of a recursive anchor once cost ~400 MB and seconds; now the first is an
// error before any tree is built.
TEST(YamlLimits, ARecursiveAliasIsAnErrorAtTheAlias) {
  std::string text = "rigc: 1\nobject:\n  fit: &f {height: 20cm";
  for (int i = 0; i < 24; ++i) text += ", k" + std::to_string(i) + ": *f";
  text += "}\n";
  const auto start = std::chrono::steady_clock::now();
  const auto problem = yaml_shape_problem(text);
  ASSERT_TRUE(problem);
  EXPECT_EQ(problem->line, 2);
  EXPECT_THAT(problem->message, HasSubstr("refers to a list or map that holds it"));
  EXPECT_LT(std::chrono::steady_clock::now() - start, std::chrono::milliseconds(200));
}

TEST(YamlLimits, AliasesThatMultiplyAreCountedWrittenOut) {
  // 8 levels of 10 repeats: 10^8 values.
  std::string text = "a0: &a0 [x, x, x, x, x, x, x, x, x, x]\n";
  for (int i = 1; i <= 8; ++i) {
    text += "a" + std::to_string(i) + ": &a" + std::to_string(i) + " [";
    for (int k = 0; k < 10; ++k) text += (k ? ", *a" : "*a") + std::to_string(i - 1);
    text += "]\n";
  }
  const auto problem = yaml_shape_problem(text);
  ASSERT_TRUE(problem);
  EXPECT_EQ(problem->line, 5);  // a5 is the first to pass kMostYamlNodes
  EXPECT_THAT(problem->message, HasSubstr("once its aliases are written out"));
}

TEST(YamlLimits, ModestAliasesAndNestingPass) {
  EXPECT_FALSE(yaml_shape_problem("a: &a {x: 1, y: [1, 2]}\nb: *a\nc: [*a, *a, {d: *a}]\n"));
  EXPECT_FALSE(yaml_shape_problem(std::string(kMostYamlDepth - 1, '[') +
                                  std::string(kMostYamlDepth - 1, ']')));
}

TEST(YamlLimits, DeepNestingIsALimitAtItsLine) {
  for (const std::string open : {"[", "{a: "}) {
    std::string text = "rigc: 1\nobject:\n  surface: ";
    std::string close;
    for (int i = 0; i < 5000; ++i) {
      text += open;
      close += open == "[" ? "]" : "}";
    }
    const auto problem = yaml_shape_problem(text + close + "\n");
    ASSERT_TRUE(problem) << open;
    EXPECT_EQ(problem->line, 2);
    EXPECT_THAT(problem->message, HasSubstr("deeper than 100 levels"));
  }
  // Block style too: each key one indent deeper.
  std::string text = "rigc: 1\nobject:\n";
  for (int i = 1; i < 2000; ++i) text += std::string(2 * i, ' ') + "k:\n";
  const auto problem = yaml_shape_problem(text);
  ASSERT_TRUE(problem);
  EXPECT_THAT(problem->message, HasSubstr("deeper than"));
}

// Through the front end the problem is a diagnostic at file:line, not "bad file".
TEST(YamlLimits, TheFrontEndReportsTheProblemAtItsLine) {
  DiagnosticEngine diag;
  std::string messages;
  rigc::testing::capture_diagnostics(diag, messages);
  const std::string text = "rigc: 1\nobject: " + std::string(3000, '[') + std::string(3000, ']');
  EXPECT_FALSE(compile_scene_text(text, "deep.yaml", ".", diag));
  EXPECT_EQ(messages.rfind("deep.yaml:2:", 0), 0u) << messages;
  EXPECT_THAT(messages, Not(HasSubstr("bad file")));
  // The echoed line is cut around the column rather than printed 6000 characters wide.
  EXPECT_LT(messages.size(), 600u) << messages;
}

}  // namespace
}  // namespace rigc
