// Starting an external renderer: always an argument vector (posix_spawn), never a shell string,
// with its output captured in a log file.
#pragma once

#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "io/child_processes.h"

namespace rigc::external {

using rigc::find_executable;

struct ProgramResult {
  bool started = false;  // false: spawn failed, `error` says why
  int exit_code = -1;    // 128 + signal when killed by a signal
  std::string error;
};

// Runs argv[0] (searched in $PATH) with `argv` in `working_dir`, stdin from /dev/null, stdout and
// stderr appended to `log_path`. Waits for it to finish.
ProgramResult run_program(const std::vector<std::string>& argv,
                          const std::filesystem::path& working_dir,
                          const std::filesystem::path& log_path);

// The last `max_lines` lines of a text file (for error messages).
std::string tail_of_file(const std::filesystem::path& path, int max_lines);

}  // namespace rigc::external
