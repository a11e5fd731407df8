#include "compiler/scene_text.h"

#include <fmt/format.h>
#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <charconv>
#include <sstream>

#include "compiler/yaml_text.h"

namespace rigc {
namespace {

constexpr std::size_t npos = std::string::npos;

std::optional<YAML::Node> load(const std::string& text, std::string* error) {
  try {
    return YAML::Load(text);
  } catch (const YAML::Exception& e) {
    *error = fmt::format("the scene is not valid YAML: {}", e.what());
    return std::nullopt;
  }
}

bool is_digits(const std::string& text) {
  return !text.empty() &&
         std::all_of(text.begin(), text.end(), [](char c) { return c >= '0' && c <= '9'; });
}

// `path` as a sweep file writes it: shots[0].turntable.
std::string path_text(const ScenePath& path, std::size_t steps) {
  std::string text;
  for (std::size_t i = 0; i < steps && i < path.size(); ++i) {
    text += is_digits(path[i]) ? "[" + path[i] + "]" : (text.empty() ? "" : ".") + path[i];
  }
  return text;
}

// One past the bracket that closes the flow collection opening at `pos` (npos if unclosed).
std::size_t flow_end(const std::string& text, std::size_t pos) {
  int depth = 0;
  for (std::size_t i = pos; i < text.size(); ++i) {
    const char c = text[i];
    if (c == '"' || c == '\'') {
      i = quoted_scalar_end(text, i);
      if (i == npos) return i;
      --i;
    } else if (c == '#' && i > 0 && (text[i - 1] == ' ' || text[i - 1] == '\t')) {
      i = text.find('\n', i);
      if (i == npos) return i;
    } else if (c == '[' || c == '{') {
      ++depth;
    } else if (c == ']' || c == '}') {
      if (--depth == 0) return i + 1;
    }
  }
  return npos;
}

bool is_flow(const std::string& text, const YAML::Node& node) {
  const std::size_t pos = node.Mark().pos;
  return pos < text.size() && (text[pos] == '[' || text[pos] == '{');
}

// One past the last character of `node`'s text, or npos when it cannot be told (a multi-line
// plain scalar, an empty value, an anchor, alias or tag before the value).
std::size_t node_end(const std::string& text, const YAML::Node& node) {
  const std::size_t pos = node.Mark().pos;
  if (pos >= text.size()) return npos;
  if (node.IsScalar()) {
    if (text[pos] == '"' || text[pos] == '\'') return quoted_scalar_end(text, pos);
    const std::string& value = node.Scalar();
    return text.compare(pos, value.size(), value) == 0 ? pos + value.size() : npos;
  }
  if (is_flow(text, node)) return flow_end(text, pos);
  if (node.IsMap() && node.size() > 0) {
    YAML::const_iterator last;
    for (auto it = node.begin(); it != node.end(); ++it) last = it;
    return node_end(text, last->second.IsNull() ? last->first : last->second);
  }
  if (node.IsSequence() && node.size() > 0) return node_end(text, node[node.size() - 1]);
  return npos;
}

std::size_t line_start(const std::string& text, std::size_t pos) {
  const std::size_t newline = pos == 0 ? npos : text.rfind('\n', pos - 1);
  return newline == npos ? 0 : newline + 1;
}

std::size_t line_end(const std::string& text, std::size_t pos) {
  const std::size_t newline = text.find('\n', pos);
  return newline == npos ? text.size() : newline;
}

// Where following a path from the root stopped.
struct Followed {
  YAML::Node node;           // the value at the path, or the last node reached
  std::size_t steps = 0;     // the steps followed: the path's size when it was found
  bool missing_key = false;  // stopped at a map without the next key
};

// The child of a map by key, or an undefined node.
YAML::Node map_child(const YAML::Node& map, const std::string& key) {
  for (auto it = map.begin(); it != map.end(); ++it) {
    if (it->first.IsScalar() && it->first.Scalar() == key) return it->second;
  }
  return YAML::Node(YAML::NodeType::Undefined);
}

// Follows `path` from `root` as far as it leads; `error` says why it stopped short. (Nodes are
// rebound with reset: yaml-cpp's operator= assigns into the tree, which then held the child in
// the root's place for the next path.)
Followed follow(const YAML::Node& root, const ScenePath& path, std::string* error) {
  Followed at{root};
  for (; at.steps < path.size(); ++at.steps) {
    const std::string& step = path[at.steps];
    const std::string walked = path_text(path, at.steps);
    const std::string here = walked.empty() ? "the scene" : "'" + walked + "'";
    if (at.node.IsSequence() && is_digits(step)) {
      std::size_t index = 0;
      std::from_chars(step.data(), step.data() + step.size(), index);
      if (index >= at.node.size()) {
        *error = fmt::format("{} has {} items, no [{}]", here, at.node.size(), step);
        return at;
      }
      at.node.reset(at.node[index]);
    } else if (at.node.IsMap() && !is_digits(step)) {
      YAML::Node next = map_child(at.node, step);
      if (!next.IsDefined()) {
        at.missing_key = true;
        *error = fmt::format("{} has no key '{}'", here, step);
        return at;
      }
      at.node.reset(next);
    } else {
      *error = is_digits(step) ? fmt::format("{} is not a list", here)
                               : fmt::format("{} has no key '{}'", here, step);
      return at;
    }
  }
  return at;
}

std::string uneditable(const ScenePath& path) {
  return fmt::format(
      "'{}' is written in a form that cannot be edited in place (a block, multi-line, anchor "
      "or tag value): write it on one line",
      path_text(path, path.size()));
}

// The span of the value `followed` reached.
std::optional<ValueSpan> span_of(const std::string& text, const ScenePath& path,
                                 const YAML::Node& node, std::string* error) {
  const YAML::Mark mark = node.Mark();
  const bool editable = node.IsScalar() || is_flow(text, node);
  const std::size_t end = editable && mark.pos >= 0 ? node_end(text, node) : npos;
  if (end == npos) {
    *error = uneditable(path);
    return std::nullopt;
  }
  return ValueSpan{static_cast<std::size_t>(mark.pos), end, mark.line + 1, mark.column + 1,
                   node.IsScalar()};
}

std::optional<ValueSpan> span_in(const std::string& text, const YAML::Node& root,
                                 const ScenePath& path, std::string* error) {
  const Followed at = follow(root, path, error);
  if (at.steps < path.size()) return std::nullopt;
  return span_of(text, path, at.node, error);
}

// Empty when every key of `path` is is_safe_key_text, else the message naming the first that
// is not.
std::string bad_key_in(const ScenePath& path) {
  for (const auto& key : path) {
    if (is_safe_key_text(key)) continue;
    std::string shown = key.substr(0, 64);
    for (char& c : shown) {
      if (static_cast<unsigned char>(c) < 0x20 || static_cast<unsigned char>(c) >= 0x7f) c = '?';
    }
    return "'" + shown + "' is not a scene key (lowercase letters, digits and underscores)";
  }
  return "";
}

bool is_path_key_char(char c) {
  return (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') || c == '_' ||
         c == '-';
}

}  // namespace

std::optional<ScenePath> parse_scene_path(const std::string& text, std::string* error) {
  const auto refuse = [&]() -> std::optional<ScenePath> {
    *error = fmt::format(
        "'{}' is not a path like camera.exposure.aperture or shots[0].turntable.steps", text);
    return std::nullopt;
  };
  ScenePath path;
  std::size_t i = 0;
  while (i < text.size()) {
    if (text[i] == '[') {
      const std::size_t close = text.find(']', i);
      if (close == npos || path.empty()) return refuse();
      const std::string index = text.substr(i + 1, close - i - 1);
      if (!is_digits(index)) return refuse();
      path.push_back(index);
      i = close + 1;
      continue;
    }
    if (text[i] == '.' && !path.empty()) ++i;
    std::size_t end = i;
    while (end < text.size() && is_path_key_char(text[end])) ++end;
    if (end == i || is_digits(text.substr(i, end - i))) return refuse();
    path.push_back(text.substr(i, end - i));
    i = end;
  }
  if (path.empty()) {
    *error = "the path is empty";
    return std::nullopt;
  }
  return path;
}

bool is_safe_value_text(const std::string& value) {
  if (value.empty() || value.size() > 200) return false;
  int depth = 0;
  for (const char c : value) {
    const bool plain = (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') ||
                       c == '.' || c == '/' || c == '+' || c == '-' || c == '_' || c == ' ';
    if (c == '[') {
      if (++depth > 1) return false;
    } else if (c == ']') {
      if (--depth < 0) return false;
    } else if (c == ',') {
      if (depth != 1) return false;
    } else if (!plain) {
      return false;
    }
  }
  if (depth != 0 || value.front() == ' ' || value.back() == ' ') return false;
  return value.front() != '-' || (value.size() > 1 && value[1] != ' ');
}

bool is_safe_key_text(const std::string& key) {
  if (key.empty() || key.size() > 64) return false;
  const auto digit = [](char c) { return c >= '0' && c <= '9'; };
  const auto word = [&](char c) { return (c >= 'a' && c <= 'z') || c == '_' || digit(c); };
  if (std::all_of(key.begin(), key.end(), digit)) return true;
  return !digit(key.front()) && std::all_of(key.begin(), key.end(), word);
}

std::string yaml_scalar_text(const std::string& value) {
  const bool plain = !value.empty() && value.front() != '-' && value.front() != '.' &&
                     std::all_of(value.begin(), value.end(), [](char c) {
                       return is_path_key_char(c) || c == '.' || c == '/' || c == '+';
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

std::optional<ValueSpan> find_value_span(const std::string& text, const ScenePath& path,
                                         std::string* error) {
  const auto root = load(text, error);
  if (!root) return std::nullopt;
  return span_in(text, *root, path, error);
}

std::optional<std::string> replace_values(
    const std::string& text, const std::vector<std::pair<ScenePath, std::string>>& values,
    std::string* error) {
  const auto root = load(text, error);
  if (!root) return std::nullopt;
  std::vector<std::pair<ValueSpan, std::string>> edits;
  for (const auto& [path, value] : values) {
    const auto span = span_in(text, *root, path, error);
    if (!span) return std::nullopt;
    edits.emplace_back(*span, value);
  }
  std::sort(edits.begin(), edits.end(),
            [](const auto& a, const auto& b) { return a.first.begin > b.first.begin; });
  for (std::size_t i = 1; i < edits.size(); ++i) {
    if (edits[i].first.end > edits[i - 1].first.begin) {
      *error = "two edits change the same value";
      return std::nullopt;
    }
  }
  std::string edited = text;
  for (const auto& [span, replacement] : edits) {
    edited.replace(span.begin, span.end - span.begin, replacement);
  }
  return edited;
}

namespace {

// Adds `key: value` to the map `map`, in its style.
std::optional<std::string> add_key(const std::string& text, const YAML::Node& map,
                                   const std::string& key, const std::string& value,
                                   std::string* error) {
  std::string result = text;
  if (is_flow(text, map)) {
    const std::size_t end = flow_end(text, map.Mark().pos);
    if (end == npos) return *error = "an unclosed flow map", std::nullopt;
    const std::size_t last = text.find_last_not_of(" \t\r\n", end - 2);
    const bool empty = last == static_cast<std::size_t>(map.Mark().pos);
    result.insert(last + 1, (empty ? "" : ", ") + key + ": " + value);
    return result;
  }
  const std::size_t end = node_end(text, map);
  if (!map.IsMap() || end == npos) {
    *error = "cannot add '" + key + "' here: the value around it is not a map that can be edited";
    return std::nullopt;
  }
  const std::string indent(map.Mark().column, ' ');
  result.insert(line_end(text, end), "\n" + indent + key + ": " + value);
  return result;
}

}  // namespace

std::optional<std::string> set_value(const std::string& text, const ScenePath& path,
                                     const std::string& value, std::string* error) {
  if (!is_safe_value_text(value)) return *error = "'" + value + "' is not a value", std::nullopt;
  if (std::string bad = bad_key_in(path); !bad.empty()) return *error = bad, std::nullopt;
  const auto root = load(text, error);
  if (!root) return std::nullopt;
  const Followed at = follow(*root, path, error);
  if (at.missing_key) {
    std::string nested = value;
    for (std::size_t j = path.size() - 1; j > at.steps; --j) {
      nested = "{" + path[j] + ": " + nested + "}";
    }
    return add_key(text, at.node, path[at.steps], nested, error);
  }
  if (at.steps < path.size()) return std::nullopt;
  const auto span = span_of(text, path, at.node, error);
  if (!span) return std::nullopt;
  std::string result = text;
  result.replace(span->begin, span->end - span->begin, value);
  return result;
}

namespace {

std::optional<YAML::Node> find_list(const std::string& text, const ScenePath& path,
                                    std::string* error) {
  if (std::string bad = bad_key_in(path); !bad.empty()) return *error = bad, std::nullopt;
  const auto root = load(text, error);
  if (!root) return std::nullopt;
  const Followed at = follow(*root, path, error);
  if (at.steps < path.size()) return std::nullopt;
  if (!at.node.IsSequence() || at.node.size() == 0) {
    *error = "'" + path_text(path, path.size()) + "' is not a non-empty list";
    return std::nullopt;
  }
  return at.node;
}

}  // namespace

std::optional<std::string> append_to_list(const std::string& text, const ScenePath& path,
                                          const std::string& entry, std::string* error) {
  const auto list = find_list(text, path, error);
  if (!list) return std::nullopt;
  const std::size_t end = node_end(text, *list);
  if (end == npos) return *error = "cannot find the list's end", std::nullopt;
  std::string result = text;
  if (is_flow(text, *list)) {
    const std::size_t last = text.find_last_not_of(" \t\r\n", end - 2);
    result.insert(last + 1, ", " + entry);
    return result;
  }
  const std::size_t first = (*list)[0].Mark().pos;
  const std::size_t dash = text.rfind('-', first);
  const std::size_t start = line_start(text, first);
  if (dash == npos || dash < start) return *error = "no list dash", std::nullopt;
  result.insert(line_end(text, end), "\n" + std::string(dash - start, ' ') + "- " + entry);
  return result;
}

std::optional<std::string> remove_from_list(const std::string& text, const ScenePath& path,
                                            std::size_t index, std::string* error) {
  const auto list = find_list(text, path, error);
  if (!list) return std::nullopt;
  if (index >= list->size()) return *error = "no such list item", std::nullopt;
  const YAML::Node item = (*list)[index];
  const std::size_t begin = item.Mark().pos, end = node_end(text, item);
  if (end == npos) return *error = "cannot find the item's end", std::nullopt;
  std::string result = text;
  if (is_flow(text, *list)) {
    // The item and the comma after it (or before it, for the last item).
    const std::size_t comma_after = text.find_first_not_of(" \t\r\n", end);
    if (comma_after < text.size() && text[comma_after] == ',') {
      const std::size_t next = text.find_first_not_of(" \t\r\n", comma_after + 1);
      return result.erase(begin, next - begin);
    }
    const std::size_t comma_before = text.find_last_not_of(" \t\r\n", begin - 1);
    const std::size_t from = text[comma_before] == ',' ? comma_before : begin;
    return result.erase(from, end - from);
  }
  const std::size_t from = line_start(text, begin);
  const std::size_t to = std::min(text.size(), line_end(text, end) + 1);
  return result.erase(from, to - from);
}

namespace {

// The byte offset where each line starts, and one past the end.
std::vector<std::size_t> line_starts(const std::string& text) {
  std::vector<std::size_t> starts = {0};
  for (std::size_t i = 0; i < text.size(); ++i) {
    if (text[i] == '\n') starts.push_back(i + 1);
  }
  if (starts.back() != text.size()) starts.push_back(text.size());
  return starts;
}

bool blank_or_comment(const std::string& text, std::size_t begin, std::size_t end) {
  const std::size_t first = text.find_first_not_of(" \t\r", begin);
  return first >= end || text[first] == '\n' || text[first] == '#';
}

// Where a top-level section is: [begin, end) in bytes, from its key's line to the next top-level
// key, comment lines just before that key left out.
struct Section {
  std::size_t begin = 0, end = 0;
  bool last = false;  // no top-level key follows
};

std::optional<Section> find_section(const std::string& text, const std::string& key,
                                    std::string* error) {
  const auto root = load(text, error);
  if (!root) return std::nullopt;
  int key_line = -1, next_line = -1;
  if (root->IsMap() && root->Style() == YAML::EmitterStyle::Block) {
    for (const auto& entry : *root) {
      const YAML::Mark mark = entry.first.Mark();
      if (entry.first.IsScalar() && entry.first.Scalar() == key && mark.column == 0) {
        key_line = mark.line;
      }
    }
    for (const auto& entry : *root) {
      const int line = entry.first.Mark().line;
      if (line > key_line && (next_line < 0 || line < next_line)) next_line = line;
    }
  }
  if (key_line < 0) {
    *error = fmt::format("the scene has no top-level `{}:` key in block style", key);
    return std::nullopt;
  }
  const std::vector<std::size_t> starts = line_starts(text);
  int end_line = next_line >= 0 ? next_line : static_cast<int>(starts.size()) - 1;
  while (end_line - 1 > key_line &&
         blank_or_comment(text, starts[end_line - 1], starts[end_line])) {
    --end_line;
  }
  return Section{starts[key_line], starts[end_line], next_line < 0};
}

// The indentation of the section's first list item ("  " when it has none).
std::string item_indent(const std::string& section) {
  std::istringstream lines(section);
  std::string line;
  std::getline(lines, line);  // the key
  while (std::getline(lines, line)) {
    const std::size_t first = line.find_first_not_of(' ');
    if (first != npos && line.compare(first, 2, "- ") == 0) return std::string(first, ' ');
  }
  return "  ";
}

}  // namespace

std::optional<std::string> replace_section(const std::string& text, const std::string& key,
                                           const std::string& section, std::string* error) {
  const auto at = find_section(text, key, error);
  if (!at) return std::nullopt;
  std::string result = text.substr(0, at->begin) + section;
  if (!at->last) result += text.substr(at->end);
  return result;
}

std::optional<std::string> append_to_section(const std::string& text, const std::string& key,
                                             const std::string& lines, std::string* error) {
  const auto at = find_section(text, key, error);
  if (!at) return std::nullopt;
  const std::string indent = item_indent(text.substr(at->begin, at->end - at->begin));
  std::istringstream in(lines);
  std::string indented;
  for (std::string line; std::getline(in, line);) {
    const std::size_t first = line.find_first_not_of(' ');
    indented += first == npos ? "\n" : indent + line.substr(first) + '\n';
  }
  std::string before = text.substr(0, at->end);
  if (!before.empty() && before.back() != '\n') before += '\n';
  return before + indented + text.substr(at->end);
}

}  // namespace rigc
