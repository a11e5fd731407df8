// Helpers shared by tests: running the rigc binary, temporary folders, source paths.
#pragma once

#include <filesystem>
#include <string>
#include <vector>

namespace rigc {
class DiagnosticEngine;
}

namespace rigc::testing {

// Appends each of `diag`'s diagnostics, rendered as rigc prints them, to `text` instead of
// printing them. `text` must outlive the engine's use.
void capture_diagnostics(DiagnosticEngine& diag, std::string& text);

// Prints none of `diag`'s diagnostics; they stay in diag.diagnostics().
void silence_diagnostics(DiagnosticEngine& diag);

struct ProcessResult {
  int exit_code = -1;
  std::string out;  // standard output
  std::string err;  // standard error
};

// Runs a program with an argument vector (no shell) and captures its output.
ProcessResult run_process(const std::vector<std::string>& argv);

// Runs the rigc binary built with the tests.
ProcessResult run_rigc(const std::vector<std::string>& args);

// A fresh empty folder under the system temp dir, removed when the object dies.
class TempDir {
 public:
  TempDir();
  ~TempDir();
  TempDir(const TempDir&) = delete;
  TempDir& operator=(const TempDir&) = delete;
  const std::filesystem::path& path() const { return path_; }
  std::string file(const std::string& name) const { return (path_ / name).string(); }

 private:
  std::filesystem::path path_;
};

// True when RIGC_REQUIRE_TOOLS=1 (scripts/test.sh sets it, and CI installs every tool): a test
// whose external tool is missing then fails instead of skipping.
bool tools_required();

std::string source_path(const std::string& relative);  // inside the repository
std::string read_text(const std::string& path);
void write_text(const std::string& path, const std::string& text);

}  // namespace rigc::testing

// Skips the test when `available` is false, naming `what` is missing; fails it instead where
// tools are required (see tools_required()).
#define RIGC_REQUIRE_TOOL(available, what)                                          \
  do {                                                                              \
    if (!(available)) {                                                             \
      if (::rigc::testing::tools_required()) FAIL() << what << " is not installed"; \
      GTEST_SKIP() << what << " is not installed";                                  \
    }                                                                               \
  } while (0)
