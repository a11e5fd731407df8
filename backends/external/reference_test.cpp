#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>

#include "backends/external/process.h"
#include "backends/external/script_text.h"
#include "tests/test_support.h"

using ::testing::HasSubstr;

namespace rigc::external {
namespace {

TEST(ReferenceScriptText, PythonLiteralEscapesEverythingThatCouldEndIt) {
  EXPECT_EQ(python_string_literal("plain text"), "\"plain text\"");
  EXPECT_EQ(python_string_literal("a\"b\\c"), "\"a\\\"b\\\\c\"");
  EXPECT_EQ(python_string_literal("line\nnext\r\t"), "\"line\\x0anext\\x0d\\x09\"");
  EXPECT_EQ(python_string_literal("caf\xC3\xA9 \xE2\x82\xAC \xF0\x9F\x98\x80"),
            "\"caf\\xe9 \\u20ac \\U0001f600\"");
  // Invalid UTF-8 (a lone continuation byte, a truncated sequence, an overlong NUL).
  EXPECT_EQ(python_string_literal("\x80x\xE2\x82"), "\"\\ufffdx\\ufffd\\ufffd\"");
  EXPECT_EQ(python_string_literal(std::string("\xC0\x80", 2)), "\"\\ufffd\\ufffd\"");
  EXPECT_EQ(python_string_literal(std::string("a\0b", 3)), "\"a\\x00b\"");
  const std::string literal = python_string_literal("\"); import os; os.system(\"touch x\")");
  // Only the two outer quotes are unescaped.
  int bare_quotes = 0;
  for (size_t i = 0; i < literal.size(); ++i) {
    if (literal[i] == '"' && (i == 0 || literal[i - 1] != '\\')) ++bare_quotes;
  }
  EXPECT_EQ(bare_quotes, 2) << literal;
}

TEST(ReferenceScriptText, PovLiteralAndComments) {
  EXPECT_EQ(*pov_string_literal("material_0.png"), "\"material_0.png\"");
  EXPECT_EQ(*pov_string_literal("a\"b\\c"), "\"a\\\"b\\\\c\"");
  EXPECT_FALSE(pov_string_literal("a\nb"));
  EXPECT_FALSE(pov_string_literal("caf\xC3\xA9"));
  EXPECT_EQ(comment_text("x\n#include \"evil\\\"\r\xC3\xA9"), "x?#include ?evil?????");
  EXPECT_EQ(number_text(0.5), "0.5");
  EXPECT_EQ(number_text(-0.0), "0");
  EXPECT_EQ(number_text(std::nan("")), "0");
  EXPECT_TRUE(is_plain_file_stem("shot_000"));
  EXPECT_FALSE(is_plain_file_stem("-shot"));
  EXPECT_FALSE(is_plain_file_stem("../x"));
  EXPECT_FALSE(is_plain_file_stem("a b"));
  EXPECT_FALSE(is_plain_file_stem(""));
}

TEST(ReferenceProcess, RunsAnArgumentVectorWithoutAShell) {
  rigc::testing::TempDir dir;
  const std::filesystem::path log = dir.path() / "log.txt";
  // A shell would expand the $ and run the ; — an argument vector passes them to echo verbatim.
  ProgramResult result =
      run_program({"echo", "$(touch pwned); touch pwned2", "`touch pwned3`"}, dir.path(), log);
  ASSERT_TRUE(result.started) << result.error;
  EXPECT_EQ(result.exit_code, 0);
  EXPECT_EQ(rigc::testing::read_text(log.string()),
            "$(touch pwned); touch pwned2 `touch pwned3`\n");
  EXPECT_FALSE(std::filesystem::exists(dir.path() / "pwned"));
  EXPECT_FALSE(std::filesystem::exists(dir.path() / "pwned2"));

  result = run_program({"sh", "-c", "pwd; exit 3"}, dir.path(), log);
  EXPECT_EQ(result.exit_code, 3);
  EXPECT_THAT(tail_of_file(log, 1), HasSubstr(dir.path().filename().string()));

  result = run_program({"rigc-no-such-renderer"}, dir.path(), log);
  EXPECT_FALSE(result.started);
  EXPECT_THAT(result.error, HasSubstr("not found"));
  EXPECT_FALSE(find_executable("rigc-no-such-renderer"));
  EXPECT_TRUE(find_executable("sh"));
}

}  // namespace
}  // namespace rigc::external
