// Programs that rigc starts (POV-Ray, Blender, COLMAP): always an argument vector (posix_spawn),
// never a shell string, with their output in a log file; and they stop when rigc is stopped.
#pragma once

#include <filesystem>
#include <optional>
#include <string>
#include <vector>

namespace rigc {

// The full path of `name` found in $PATH (or `name` itself when it contains a '/' and is
// executable); nullopt when there is none.
std::optional<std::filesystem::path> find_executable(const std::string& name);

struct ChildRun {
  std::vector<std::string> argv;      // argv[0] is searched in $PATH
  std::filesystem::path log;          // stdout and stderr are appended here; stdin is /dev/null
  std::filesystem::path working_dir;  // empty: rigc's own
  // NAME=value entries added to rigc's environment, each only where NAME is not set already.
  std::vector<std::string> default_env;
};

struct ChildResult {
  bool started = false;  // false: it could not be started, `error` says why
  int exit_code = -1;    // 128 + signal when killed by a signal; -1 when the wait failed
  double cpu_seconds = 0;
  std::string error;
};

// Runs the program and waits for it. While it runs, a SIGINT, SIGTERM or SIGHUP that stops rigc
// sends it a SIGTERM first, so that a signal sent to rigc alone (`kill`, `timeout`, a closed ssh
// session) does not leave a renderer writing into a folder a rerun renders into. A signal that
// comes while the child is being started stops it too. (A SIGKILL cannot be caught: the child then
// runs on.)
ChildResult run_child(const ChildRun& run);

// Sends a SIGTERM to every program rigc is running (the studio's Cancel of a reference render);
// run_child then returns with 128 + SIGTERM.
void stop_child_processes();

// Tests only: `hook` runs in run_child between the child's spawn and its watch, where a stop
// signal has to be deferred (nullptr: none).
void set_spawn_hook_for_tests(void (*hook)());

}  // namespace rigc
