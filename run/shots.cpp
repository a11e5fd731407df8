#include "run/shots.h"

#include <fmt/format.h>

#include <algorithm>
#include <charconv>
#include <string_view>

namespace rigc::run {
namespace {

std::string_view trim(std::string_view s) {
  while (!s.empty() && (s.front() == ' ' || s.front() == '\t')) s.remove_prefix(1);
  while (!s.empty() && (s.back() == ' ' || s.back() == '\t')) s.remove_suffix(1);
  return s;
}

// A non-negative decimal integer and nothing else; values beyond int are clamped to INT_MAX so
// that they are reported as out of range rather than as garbage.
std::optional<long long> parse_index(std::string_view s) {
  s = trim(s);
  if (s.empty() || !std::all_of(s.begin(), s.end(), [](char c) { return c >= '0' && c <= '9'; })) {
    return std::nullopt;
  }
  long long value = 0;
  const auto [end, ec] = std::from_chars(s.data(), s.data() + s.size(), value);
  if (ec == std::errc::result_out_of_range) return static_cast<long long>(1) << 40;
  if (ec != std::errc() || end != s.data() + s.size()) return std::nullopt;
  return value;
}

}  // namespace

std::optional<std::vector<int>> parse_shot_selection(const std::string& text, int shot_count,
                                                     std::string* error) {
  auto fail = [&](std::string message) -> std::optional<std::vector<int>> {
    if (error != nullptr) *error = std::move(message);
    return std::nullopt;
  };
  const std::string range = shot_count > 0 ? fmt::format("valid shots are 0..{}", shot_count - 1)
                                           : "the scene has no shots";
  const std::string_view all = trim(text);
  std::vector<int> selected;
  // An empty `--shots ''` is refused rather than read as "all": it is usually a shell variable
  // that came out empty, and rendering every shot of a big scene is not what was meant.
  if (all.empty()) {
    return fail(
        fmt::format("the shot selection is empty: give indices and ranges like 0,3,5-7 "
                    "or 'all' ({})",
                    range));
  }
  if (all == "all") {
    for (int i = 0; i < shot_count; ++i) selected.push_back(i);
    return selected;
  }
  std::string_view rest = all;
  while (true) {
    const std::size_t comma = rest.find(',');
    const std::string_view item = trim(rest.substr(0, comma));
    const std::size_t dash = item.find('-');
    const auto first = parse_index(item.substr(0, dash));
    const auto last = dash == std::string_view::npos ? first : parse_index(item.substr(dash + 1));
    if (!first || !last) {
      return fail(fmt::format(
          "cannot read shot selection '{}' at '{}': expected indices and ranges like 0,3,5-7 "
          "({})",
          text, item, range));
    }
    if (*first >= shot_count || *last >= shot_count) {
      return fail(fmt::format("{} {} {} out of range: {}",
                              dash == std::string_view::npos ? "shot" : "shots", item,
                              dash == std::string_view::npos ? "is" : "are", range));
    }
    if (*last < *first) {
      return fail(fmt::format("shot range {}-{} is reversed: write {}-{} ({})", *first, *last,
                              *last, *first, range));
    }
    for (long long i = *first; i <= *last; ++i) selected.push_back(static_cast<int>(i));
    if (comma == std::string_view::npos) break;
    rest = rest.substr(comma + 1);
  }
  std::sort(selected.begin(), selected.end());
  selected.erase(std::unique(selected.begin(), selected.end()), selected.end());
  return selected;
}

}  // namespace rigc::run
