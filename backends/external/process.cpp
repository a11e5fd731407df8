#include "backends/external/process.h"

#include <deque>
#include <fstream>

namespace rigc::external {

namespace fs = std::filesystem;

ProgramResult run_program(const std::vector<std::string>& argv, const fs::path& working_dir,
                          const fs::path& log_path) {
  const rigc::ChildResult child = rigc::run_child({argv, log_path, working_dir, {}});
  return {child.started, child.exit_code, child.error};
}

std::string tail_of_file(const fs::path& path, int max_lines) {
  std::ifstream in(path);
  std::deque<std::string> lines;
  std::string line;
  while (std::getline(in, line)) {
    lines.push_back(line);
    if (static_cast<int>(lines.size()) > max_lines) lines.pop_front();
  }
  std::string text;
  for (const auto& l : lines) text += l + "\n";
  return text;
}

}  // namespace rigc::external
