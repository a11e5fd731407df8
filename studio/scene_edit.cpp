#include "studio/scene_edit.h"

#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <charconv>

#include "compiler/yaml_text.h"

namespace rigc::studio {
namespace {

// One past the bracket that closes the flow collection opening at `pos` (npos if unclosed).
size_t flow_end(const std::string& text, size_t pos) {
  int depth = 0;
  for (size_t i = pos; i < text.size(); ++i) {
    const char c = text[i];
    if (c == '"' || c == '\'') {
      i = quoted_scalar_end(text, i);
      if (i == std::string::npos) return i;
      --i;
    } else if (c == '#' && i > 0 && (text[i - 1] == ' ' || text[i - 1] == '\t')) {
      i = text.find('\n', i);
      if (i == std::string::npos) return i;
    } else if (c == '[' || c == '{') {
      ++depth;
    } else if (c == ']' || c == '}') {
      if (--depth == 0) return i + 1;
    }
  }
  return std::string::npos;
}

bool is_flow(const std::string& text, const YAML::Node& node) {
  const size_t pos = node.Mark().pos;
  return pos < text.size() && (text[pos] == '[' || text[pos] == '{');
}

// One past the last character of `node`'s text, or npos when it cannot be told (a multi-line
// plain scalar, an empty value).
size_t node_end(const std::string& text, const YAML::Node& node) {
  const size_t pos = node.Mark().pos;
  if (pos >= text.size()) return std::string::npos;
  if (node.IsScalar()) {
    if (text[pos] == '"' || text[pos] == '\'') return quoted_scalar_end(text, pos);
    const std::string& value = node.Scalar();
    return text.compare(pos, value.size(), value) == 0 ? pos + value.size() : std::string::npos;
  }
  if (is_flow(text, node)) return flow_end(text, pos);
  if (node.IsMap() && node.size() > 0) {
    YAML::const_iterator last;
    for (auto it = node.begin(); it != node.end(); ++it) last = it;
    return node_end(text, last->second.IsNull() ? last->first : last->second);
  }
  if (node.IsSequence() && node.size() > 0) return node_end(text, node[node.size() - 1]);
  return std::string::npos;
}

size_t line_start(const std::string& text, size_t pos) {
  const size_t newline = pos == 0 ? std::string::npos : text.rfind('\n', pos - 1);
  return newline == std::string::npos ? 0 : newline + 1;
}

size_t line_end(const std::string& text, size_t pos) {
  const size_t newline = text.find('\n', pos);
  return newline == std::string::npos ? text.size() : newline;
}

std::optional<YAML::Node> load(const std::string& text, std::string* error) {
  try {
    return YAML::Load(text);
  } catch (const YAML::Exception& e) {
    *error = e.what();
    return std::nullopt;
  }
}

// The child of a map by key or of a list by index; an undefined node when there is none.
YAML::Node child(const YAML::Node& node, const std::string& key, std::string* error) {
  if (node.IsMap()) {
    for (auto it = node.begin(); it != node.end(); ++it) {
      if (it->first.IsScalar() && it->first.Scalar() == key) return it->second;
    }
    return YAML::Node(YAML::NodeType::Undefined);
  }
  if (node.IsSequence()) {
    size_t index = 0;
    const auto [end, ec] = std::from_chars(key.data(), key.data() + key.size(), index);
    if (ec == std::errc() && end == key.data() + key.size() && index < node.size()) {
      return node[index];
    }
    *error = "no list item " + key;
    return YAML::Node(YAML::NodeType::Undefined);
  }
  *error = "'" + key + "' is inside a value that is not a map or a list";
  return YAML::Node(YAML::NodeType::Undefined);
}

// Adds `key: value` to the map `map`, in its style.
std::optional<std::string> add_key(const std::string& text, const YAML::Node& map,
                                   const std::string& key, const std::string& value,
                                   std::string* error) {
  std::string result = text;
  if (is_flow(text, map)) {
    const size_t end = flow_end(text, map.Mark().pos);
    if (end == std::string::npos) return *error = "an unclosed flow map", std::nullopt;
    const size_t last = text.find_last_not_of(" \t\r\n", end - 2);
    const bool empty = last == static_cast<size_t>(map.Mark().pos);
    result.insert(last + 1, (empty ? "" : ", ") + key + ": " + value);
    return result;
  }
  const size_t end = node_end(text, map);
  if (!map.IsMap() || end == std::string::npos) {
    *error = "cannot add '" + key + "' here: the value around it is not a map the studio can edit";
    return std::nullopt;
  }
  const std::string indent(map.Mark().column, ' ');
  result.insert(line_end(text, end), "\n" + indent + key + ": " + value);
  return result;
}

}  // namespace

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

namespace {

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

}  // namespace

std::optional<std::string> set_value(const std::string& text, const ScenePath& path,
                                     const std::string& value, std::string* error) {
  if (!is_safe_value_text(value)) return *error = "'" + value + "' is not a value", std::nullopt;
  if (std::string bad = bad_key_in(path); !bad.empty()) return *error = bad, std::nullopt;
  const auto root = load(text, error);
  if (!root) return std::nullopt;
  YAML::Node node = *root;
  for (size_t i = 0; i < path.size(); ++i) {
    error->clear();
    YAML::Node next = child(node, path[i], error);
    if (!error->empty()) return std::nullopt;
    if (!next.IsDefined()) {
      std::string nested = value;
      for (size_t j = path.size() - 1; j > i; --j) nested = "{" + path[j] + ": " + nested + "}";
      return add_key(text, node, path[i], nested, error);
    }
    node = next;
  }
  const size_t begin = node.Mark().pos;
  const size_t end = node_end(text, node);
  if (end == std::string::npos || !(node.IsScalar() || is_flow(text, node))) {
    *error = "the value is written in a form the studio cannot edit (a block or multi-line value)";
    return std::nullopt;
  }
  std::string result = text;
  result.replace(begin, end - begin, value);
  return result;
}

namespace {

std::optional<YAML::Node> find_list(const std::string& text, const ScenePath& path,
                                    std::string* error) {
  if (std::string bad = bad_key_in(path); !bad.empty()) return *error = bad, std::nullopt;
  auto root = load(text, error);
  if (!root) return std::nullopt;
  YAML::Node node = *root;
  for (const auto& key : path) {
    error->clear();
    node = child(node, key, error);
    if (!error->empty()) return std::nullopt;
    if (!node.IsDefined()) return *error = "the scene has no '" + key + "'", std::nullopt;
  }
  if (!node.IsSequence() || node.size() == 0) {
    return *error = "'" + path.back() + "' is not a non-empty list", std::nullopt;
  }
  return node;
}

}  // namespace

std::optional<std::string> append_to_list(const std::string& text, const ScenePath& path,
                                          const std::string& entry, std::string* error) {
  const auto list = find_list(text, path, error);
  if (!list) return std::nullopt;
  const size_t end = node_end(text, *list);
  if (end == std::string::npos) return *error = "cannot find the list's end", std::nullopt;
  std::string result = text;
  if (is_flow(text, *list)) {
    const size_t last = text.find_last_not_of(" \t\r\n", end - 2);
    result.insert(last + 1, ", " + entry);
    return result;
  }
  const size_t first = (*list)[0].Mark().pos;
  const size_t dash = text.rfind('-', first);
  const size_t start = line_start(text, first);
  if (dash == std::string::npos || dash < start) return *error = "no list dash", std::nullopt;
  result.insert(line_end(text, end), "\n" + std::string(dash - start, ' ') + "- " + entry);
  return result;
}

std::optional<std::string> remove_from_list(const std::string& text, const ScenePath& path,
                                            size_t index, std::string* error) {
  const auto list = find_list(text, path, error);
  if (!list) return std::nullopt;
  if (index >= list->size()) return *error = "no such list item", std::nullopt;
  const YAML::Node item = (*list)[index];
  const size_t begin = item.Mark().pos, end = node_end(text, item);
  if (end == std::string::npos) return *error = "cannot find the item's end", std::nullopt;
  std::string result = text;
  if (is_flow(text, *list)) {
    // The item and the comma after it (or before it, for the last item).
    const size_t comma_after = text.find_first_not_of(" \t\r\n", end);
    if (comma_after < text.size() && text[comma_after] == ',') {
      const size_t next = text.find_first_not_of(" \t\r\n", comma_after + 1);
      return result.erase(begin, next - begin);
    }
    const size_t comma_before = text.find_last_not_of(" \t\r\n", begin - 1);
    const size_t from = text[comma_before] == ',' ? comma_before : begin;
    return result.erase(from, end - from);
  }
  const size_t from = line_start(text, begin);
  const size_t to = std::min(text.size(), line_end(text, end) + 1);
  return result.erase(from, to - from);
}

}  // namespace rigc::studio
