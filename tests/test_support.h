// Helpers shared by tests: running the rigc binary, temporary folders, source paths.
#pragma once

#include <filesystem>
#include <string>
#include <vector>

namespace rigc::testing {

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

std::string source_path(const std::string& relative);  // inside the repository
std::string read_text(const std::string& path);
void write_text(const std::string& path, const std::string& text);

}  // namespace rigc::testing
