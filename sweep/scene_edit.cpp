#include "sweep/scene_edit.h"

#include <fmt/format.h>
#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <charconv>

#include "compiler/yaml_text.h"

namespace rigc::sweep {
namespace {

bool is_key_char(char c) {
  return (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') || c == '_' ||
         c == '-';
}

// The end of a plain scalar starting at `begin`: the line's end, a comment, or in a flow
// collection the next ',', ']' or '}'; trailing blanks left out.
std::size_t plain_end(const std::string& text, std::size_t begin, bool in_flow) {
  std::size_t i = begin;
  for (; i < text.size(); ++i) {
    const char c = text[i];
    if (c == '\n' || c == '\r') break;
    if (c == '#' && i > begin && (text[i - 1] == ' ' || text[i - 1] == '\t')) break;
    if (in_flow && (c == ',' || c == ']' || c == '}')) break;
  }
  while (i > begin && (text[i - 1] == ' ' || text[i - 1] == '\t')) --i;
  return i;
}

// Follows `steps` from `root`; sets `in_flow` when a collection on the way is written in flow
// style (`{a: 1}`, `[1, 2]`). An invalid node when a step is missing; `error` says which.
YAML::Node follow(const YAML::Node& root, const std::vector<PathStep>& steps, bool* in_flow,
                  std::string* error) {
  YAML::Node node = root;
  std::string walked;
  for (const PathStep& step : steps) {
    if (node.Style() == YAML::EmitterStyle::Flow) *in_flow = true;
    const std::string here = walked.empty() ? "the scene" : "'" + walked + "'";
    if (!step.key.empty()) {
      if (!node.IsMap() || !node[step.key]) {
        *error = fmt::format("{} has no key '{}'", here, step.key);
        return YAML::Node(YAML::NodeType::Undefined);
      }
      node = node[step.key];
      walked += (walked.empty() ? "" : ".") + step.key;
    } else {
      if (!node.IsSequence() || step.index >= static_cast<int>(node.size())) {
        *error = node.IsSequence()
                     ? fmt::format("{} has {} items, no [{}]", here, node.size(), step.index)
                     : fmt::format("{} is not a list", here);
        return YAML::Node(YAML::NodeType::Undefined);
      }
      node = node[step.index];
      walked += fmt::format("[{}]", step.index);
    }
  }
  return node;
}

}  // namespace

std::optional<std::vector<PathStep>> parse_value_path(const std::string& path, std::string* error) {
  std::vector<PathStep> steps;
  std::size_t i = 0;
  while (i < path.size()) {
    if (path[i] == '[') {
      const std::size_t close = path.find(']', i);
      int index = -1;
      const auto [end, ec] =
          std::from_chars(path.data() + i + 1, path.data() + std::min(close, path.size()), index);
      if (close == std::string::npos || ec != std::errc() || end != path.data() + close ||
          index < 0 || steps.empty()) {
        *error = fmt::format(
            "'{}' is not a path like camera.exposure.aperture or "
            "shots[0].turntable.steps",
            path);
        return std::nullopt;
      }
      steps.push_back({"", index});
      i = close + 1;
      continue;
    }
    if (path[i] == '.' && !steps.empty()) ++i;
    std::size_t end = i;
    while (end < path.size() && is_key_char(path[end])) ++end;
    if (end == i) {
      *error = fmt::format(
          "'{}' is not a path like camera.exposure.aperture or "
          "shots[0].turntable.steps",
          path);
      return std::nullopt;
    }
    steps.push_back({path.substr(i, end - i), -1});
    i = end;
  }
  if (steps.empty()) {
    *error = "the path is empty";
    return std::nullopt;
  }
  return steps;
}

std::optional<ValueSpan> find_value_span(const std::string& text, const std::string& path,
                                         std::string* error) {
  const auto steps = parse_value_path(path, error);
  if (!steps) return std::nullopt;
  YAML::Node root;
  try {
    root = YAML::Load(text);
  } catch (const YAML::Exception& e) {
    *error = fmt::format("the scene is not valid YAML: {}", e.msg);
    return std::nullopt;
  }
  bool in_flow = false;
  const YAML::Node node = follow(root, *steps, &in_flow, error);
  if (!node.IsDefined()) return std::nullopt;
  if (!node.IsScalar()) {
    *error = fmt::format("'{}' is not a single value in the scene (a sweep varies scalars)", path);
    return std::nullopt;
  }
  const YAML::Mark mark = node.Mark();
  if (mark.pos < 0 || static_cast<std::size_t>(mark.pos) >= text.size()) {
    *error = fmt::format("'{}' has no place in the scene's text", path);
    return std::nullopt;
  }
  const std::size_t begin = static_cast<std::size_t>(mark.pos);
  const char first = text[begin];
  std::size_t end = std::string::npos;
  if (first == '"' || first == '\'') {
    end = quoted_scalar_end(text, begin);
  } else if (first != '|' && first != '>' && first != '&' && first != '!' && first != '*') {
    end = plain_end(text, begin, in_flow);
    // A plain scalar folded over several lines would not end at the line's end.
    if (text.substr(begin, end - begin) != node.Scalar()) end = std::string::npos;
  }
  if (end == std::string::npos) {
    *error = fmt::format(
        "'{}' is written in a form a sweep cannot edit (block, multi-line, "
        "anchor or tag): write it on one line",
        path);
    return std::nullopt;
  }
  return ValueSpan{begin, end, mark.line + 1, mark.column + 1};
}

std::string yaml_scalar_text(const std::string& value) {
  const bool plain = !value.empty() && value.front() != '-' && value.front() != '.' &&
                     std::all_of(value.begin(), value.end(), [](char c) {
                       return is_key_char(c) || c == '.' || c == '/' || c == '+';
                     });
  if (plain || (value.size() > 1 && value.front() == '-' &&
                std::all_of(value.begin() + 1, value.end(),
                            [](char c) { return (c >= '0' && c <= '9') || c == '.'; }))) {
    return value;
  }
  std::string quoted = "\"";
  for (const unsigned char c : value) {
    if (c == '"' || c == '\\') {
      quoted += '\\';
      quoted += static_cast<char>(c);
    } else if (c < 0x20 || c == 0x7F) {
      quoted += fmt::format("\\x{:02x}", c);
    } else {
      quoted += static_cast<char>(c);
    }
  }
  return quoted + "\"";
}

std::optional<std::string> edit_scene_text(
    const std::string& text, const std::vector<std::pair<std::string, std::string>>& values,
    std::string* error) {
  std::vector<std::pair<ValueSpan, std::string>> edits;
  for (const auto& [path, value] : values) {
    const auto span = find_value_span(text, path, error);
    if (!span) return std::nullopt;
    edits.emplace_back(*span, yaml_scalar_text(value));
  }
  std::sort(edits.begin(), edits.end(),
            [](const auto& a, const auto& b) { return a.first.begin > b.first.begin; });
  for (std::size_t i = 1; i < edits.size(); ++i) {
    if (edits[i].first.begin == edits[i - 1].first.begin) {
      *error = "two axes vary the same value";
      return std::nullopt;
    }
  }
  std::string edited = text;
  for (const auto& [span, replacement] : edits) {
    edited.replace(span.begin, span.end - span.begin, replacement);
  }
  return edited;
}

}  // namespace rigc::sweep
