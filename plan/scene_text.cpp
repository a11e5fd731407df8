#include "plan/scene_text.h"

#include <yaml-cpp/yaml.h>

#include <sstream>
#include <vector>

namespace rigc::plan {
namespace {

// The byte offset where each line starts, and one past the end.
std::vector<size_t> line_starts(const std::string& text) {
  std::vector<size_t> starts = {0};
  for (size_t i = 0; i < text.size(); ++i) {
    if (text[i] == '\n') starts.push_back(i + 1);
  }
  if (starts.back() != text.size()) starts.push_back(text.size());
  return starts;
}

bool blank_or_comment(const std::string& text, size_t begin, size_t end) {
  const size_t first = text.find_first_not_of(" \t\r", begin);
  return first >= end || text[first] == '\n' || text[first] == '#';
}

// Where the `shots:` section is: [begin, end) in bytes, from its key's line to the next top-level
// key, comment lines just before that key left out.
struct Section {
  size_t begin = 0, end = 0;
  bool last = false;  // no top-level key follows
};

std::optional<Section> find_shots_section(const std::string& text, std::string* error) {
  YAML::Node root;
  try {
    root = YAML::Load(text);
  } catch (const YAML::Exception& e) {
    if (error) *error = e.what();
    return std::nullopt;
  }
  int shots_line = -1, next_line = -1;
  if (root.IsMap() && root.Style() == YAML::EmitterStyle::Block) {
    for (const auto& entry : root) {
      const YAML::Mark mark = entry.first.Mark();
      if (entry.first.IsScalar() && entry.first.Scalar() == "shots" && mark.column == 0) {
        shots_line = mark.line;
      }
    }
    for (const auto& entry : root) {
      const int line = entry.first.Mark().line;
      if (line > shots_line && (next_line < 0 || line < next_line)) next_line = line;
    }
  }
  if (shots_line < 0) {
    if (error) *error = "the scene has no top-level `shots:` key in block style to replace";
    return std::nullopt;
  }
  const std::vector<size_t> starts = line_starts(text);
  int end_line = next_line >= 0 ? next_line : static_cast<int>(starts.size()) - 1;
  while (end_line - 1 > shots_line &&
         blank_or_comment(text, starts[end_line - 1], starts[end_line])) {
    --end_line;
  }
  return Section{starts[shots_line], starts[end_line], next_line < 0};
}

// The indentation of the section's first list item ("  " when it has none).
std::string item_indent(const std::string& section) {
  std::istringstream lines(section);
  std::string line;
  std::getline(lines, line);  // the key
  while (std::getline(lines, line)) {
    const size_t first = line.find_first_not_of(' ');
    if (first != std::string::npos && line.compare(first, 2, "- ") == 0) {
      return std::string(first, ' ');
    }
  }
  return "  ";
}

}  // namespace

std::optional<std::string> replace_shots_section(const std::string& text,
                                                 const std::string& shots_section,
                                                 std::string* error) {
  const auto section = find_shots_section(text, error);
  if (!section) return std::nullopt;
  std::string result = text.substr(0, section->begin) + shots_section;
  if (!section->last) result += text.substr(section->end);
  return result;
}

std::optional<std::string> append_to_shots_section(const std::string& text,
                                                   const std::string& entries, std::string* error) {
  const auto section = find_shots_section(text, error);
  if (!section) return std::nullopt;
  const std::string indent =
      item_indent(text.substr(section->begin, section->end - section->begin));
  std::istringstream lines(entries);
  std::string indented;
  for (std::string line; std::getline(lines, line);) {
    indented += indent + line.substr(line.find_first_not_of(' ')) + '\n';
  }
  std::string before = text.substr(0, section->end);
  if (!before.empty() && before.back() != '\n') before += '\n';
  return before + indented + text.substr(section->end);
}

}  // namespace rigc::plan
