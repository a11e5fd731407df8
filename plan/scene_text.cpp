#include "plan/scene_text.h"

#include <yaml-cpp/yaml.h>

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

}  // namespace

std::optional<std::string> replace_shots_section(const std::string& text,
                                                 const std::string& shots_section,
                                                 std::string* error) {
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
  while (next_line >= 0 && end_line - 1 > shots_line &&
         blank_or_comment(text, starts[end_line - 1], starts[end_line])) {
    --end_line;
  }
  std::string result = text.substr(0, starts[shots_line]) + shots_section;
  if (next_line >= 0) result += text.substr(starts[end_line]);
  return result;
}

}  // namespace rigc::plan
