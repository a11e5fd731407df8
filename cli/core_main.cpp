// `rigc`: the verbs that need only the compiler and the coverage analysis (check, version and
// the usage) run in this small binary; the others run in rigc-all beside it, whose ~300 shared
// libraries (the renderers', COLMAP's, Open3D's, the studio's) take 0.3-0.9 s to load.
#include <fmt/format.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <filesystem>
#include <iostream>

#include "cli/dispatch.h"
#include "cli/standard_streams.h"
#include "cli/verbs.h"
#include "io/allocator.h"
#include "io/input_files.h"

int main(int argc, char** argv) {
  rigc::cli::guard_standard_streams();
  rigc::keep_freed_memory();
  rigc::enable_input_protection();
  // The other verbs: the same arguments to rigc-all, in this process.
  auto run_in_rigc_all = [argv](const std::vector<std::string>&) {
    std::error_code error;
    const std::filesystem::path self = std::filesystem::read_symlink("/proc/self/exe", error);
    const std::filesystem::path all = self.parent_path() / "rigc-all";
    execv(all.c_str(), argv);
    std::cerr << fmt::format("rigc: error: cannot start {}: {}\n", all.string(),
                             std::strerror(errno));
    return rigc::cli::kExitInternalError;
  };
  const std::vector<rigc::cli::Command> core = rigc::cli::table_of(
      {{"check", rigc::cli::run_check_command}, {"version", rigc::cli::run_version_command}});
  const int code =
      rigc::cli::dispatch(std::vector<std::string>(argv, argv + argc), core, run_in_rigc_all);
  return rigc::cli::finish_standard_output(code);
}
