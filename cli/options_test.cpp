#include "cli/options.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <sstream>

using ::testing::HasSubstr;

namespace rigc::cli {
namespace {

// Parses `--value TEXT` through positive_number(); returns the error text ("" when accepted).
std::string parse_value(const std::string& text, double* value) {
  CLI::App app;
  app.add_option("--value", *value)->check(positive_number());
  std::ostringstream ignored;
  std::streambuf* old = std::cerr.rdbuf(ignored.rdbuf());
  const std::optional<int> code = parse_options(app, {"rigc", "--value", text});
  std::cerr.rdbuf(old);
  return code ? ignored.str() : std::string();
}

TEST(CommandLine, DecimalNumbersInEveryUsualFormAreTaken) {
  const std::vector<std::pair<std::string, double>> valid = {
      {"1e-3", 1e-3}, {".5", 0.5}, {"5.", 5}, {"+2", 2}, {"1E3", 1000}, {"0.25", 0.25}};
  for (const auto& [text, expected] : valid) {
    double value = 0;
    EXPECT_EQ(parse_value(text, &value), "") << text;
    EXPECT_DOUBLE_EQ(value, expected) << text;
  }
}

TEST(CommandLine, AnythingElseIsNamed) {
  const std::vector<std::pair<std::string, std::string>> invalid = {
      {"0x1", "'0x1' is not a number"},
      {"+-2", "'+-2' is not a number"},
      {"2cm", "'2cm' is not a number"},
      {"", "is not a number"},
      {"nan", "'nan' is not a finite number"},
      {"inf", "'inf' is not a finite number"},
      {"1e400", "'1e400' is out of range"},
      {"-1", "'-1' is not above 0"},
      {"0", "'0' is not above 0"}};
  for (const auto& [text, message] : invalid) {
    double value = 0;
    const std::string error = parse_value(text, &value);
    EXPECT_THAT(error, HasSubstr("rigc: error: ")) << text << ": " << error;
    EXPECT_THAT(error, HasSubstr(message)) << text << ": " << error;
  }
}

// CLI11 read a seed of 99999999999999999999 as 2^64 - 1 without a word.
TEST(CommandLine, ASeedOutOfRangeIsAnError) {
  auto parse_seed = [](const std::string& text, std::uint64_t* seed) {
    CLI::App app;
    app.add_option("--seed", *seed)->check(unsigned_64_number());
    std::ostringstream errors;
    std::streambuf* old = std::cerr.rdbuf(errors.rdbuf());
    const std::optional<int> code = parse_options(app, {"rigc", "--seed", text});
    std::cerr.rdbuf(old);
    return code ? errors.str() : std::string();
  };
  std::uint64_t seed = 0;
  EXPECT_EQ(parse_seed("18446744073709551615", &seed), "");
  EXPECT_EQ(seed, 18446744073709551615u);
  EXPECT_EQ(parse_seed("0", &seed), "");
  EXPECT_THAT(parse_seed("99999999999999999999", &seed),
              HasSubstr("'99999999999999999999' is out of range: give 0 to 18446744073709551615"));
  EXPECT_THAT(parse_seed("18446744073709551616", &seed), HasSubstr("out of range"));
  EXPECT_THAT(parse_seed("-1", &seed), HasSubstr("'-1' is negative"));
  EXPECT_THAT(parse_seed("1.5", &seed), HasSubstr("not a whole number"));
  EXPECT_THAT(parse_seed("0x10", &seed), HasSubstr("not a whole number"));
}

}  // namespace
}  // namespace rigc::cli
