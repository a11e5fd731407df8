// What the verbs in cli/ and eval/ share about their options (CLI11).
#pragma once

#include <CLI/CLI.hpp>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <iostream>
#include <optional>
#include <string>
#include <utility>
#include <vector>

namespace rigc::cli {

// Parses a verb's options; returns the exit code when parsing ended the run (0 after --help, 1
// after an error, printed as `rigc: error: ...` like every other error of rigc).
inline std::optional<int> parse_options(CLI::App& app, const std::vector<std::string>& args) {
  std::vector<const char*> argv;
  for (const auto& a : args) argv.push_back(a.c_str());
  try {
    app.parse(static_cast<int>(argv.size()), argv.data());
  } catch (const CLI::ParseError& e) {
    if (e.get_exit_code() == static_cast<int>(CLI::ExitCodes::Success)) return app.exit(e);
    std::cerr << "rigc: error: " << e.what() << "\nRun with --help for more information.\n";
    return 1;
  }
  return std::nullopt;
}

// A number that is not NaN or infinite and that `accept` takes; otherwise the option's error is
// the text and `complaint`. CLI11's Range and PositiveNumber let NaN through (every comparison
// with it is false): `rigc render --scale nan` rendered a shot, recorded it in the manifest
// without its files and failed only at the end. Their messages also print a bound of 1.8e308 in
// full, and CLI11 reads "-1" into an unsigned option as 2^64 - 1. Only decimal numbers are
// taken: strtod, under CLI11, also reads hexadecimal ("0x1" was a scale of 1).
template <typename Accept>
CLI::Validator finite_number_where(Accept accept, std::string complaint, std::string name) {
  return CLI::Validator(
      [accept, complaint](std::string& text) -> std::string {
        double value = 0;
        const char* first = text.data() + (text.starts_with('+') ? 1 : 0);
        const char* last = text.data() + text.size();
        const auto [end, error] = std::from_chars(first, last, value, std::chars_format::general);
        // "+-2" is no number; 1e400 parses but is out of a double's range.
        const bool signed_twice = first != text.data() && first != last && *first == '-';
        if (first == last || signed_twice || end != last ||
            (error != std::errc() && error != std::errc::result_out_of_range)) {
          return "'" + text + "' is not a number";
        }
        if (error == std::errc::result_out_of_range) return "'" + text + "' is out of range";
        if (!std::isfinite(value)) return "'" + text + "' is not a finite number";
        return accept(value) ? std::string() : "'" + text + "' " + complaint;
      },
      std::move(name));
}

// Check with this before a range (it adds nothing to the option's help line).
inline const CLI::Validator& finite_number() {
  static const CLI::Validator check = finite_number_where([](double) { return true; }, "", "");
  return check;
}
inline const CLI::Validator& non_negative_number() {
  static const CLI::Validator check = finite_number_where(
      [](double value) { return value >= 0; }, "is negative: give 0 or more", "NONNEGATIVE");
  return check;
}
// A whole number 0..2^64-1 (a seed): CLI11 read 99999999999999999999 as 2^64 - 1, silently.
inline const CLI::Validator& unsigned_64_number() {
  static const CLI::Validator check(
      [](std::string& text) -> std::string {
        std::uint64_t value = 0;
        const char* first = text.data() + (text.starts_with('+') ? 1 : 0);
        const char* last = text.data() + text.size();
        if (first != last && *first == '-') return "'" + text + "' is negative: give 0 or more";
        const auto [end, error] = std::from_chars(first, last, value);
        if (error == std::errc::result_out_of_range) {
          return "'" + text + "' is out of range: give 0 to 18446744073709551615";
        }
        if (first == last || end != last || error != std::errc()) {
          return "'" + text + "' is not a whole number 0 or more";
        }
        return "";
      },
      "UINT64");
  return check;
}
inline const CLI::Validator& positive_number() {
  static const CLI::Validator check =
      finite_number_where([](double value) { return value > 0; }, "is not above 0", "POSITIVE");
  return check;
}

// Where render and sweep run their work: here, or as Slurm array tasks.
enum class Executor { local, slurm };

// --executor local|slurm into `executor`; another name is an option error that lists the two.
inline CLI::Option* add_executor_option(CLI::App& app, Executor& executor,
                                        const std::string& description) {
  static const std::vector<std::pair<std::string, Executor>> names = {{"local", Executor::local},
                                                                      {"slurm", Executor::slurm}};
  return app.add_option("--executor", executor, description)
      ->transform(CLI::CheckedTransformer(names))
      ->default_str("local");
}

}  // namespace rigc::cli
