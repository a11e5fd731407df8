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
#include "cli/verb_list.h"
#include "cli/verbs.h"
#include "io/allocator.h"
#include "io/input_files.h"

namespace {

// The core's verbs, with the usage's summaries.
std::vector<rigc::cli::Command> core_commands() {
  std::vector<rigc::cli::Command> out;
  for (const rigc::cli::VerbSummary& verb : rigc::cli::verb_summaries()) {
    if (verb.name == "check")
      out.push_back({verb.name, verb.summary, rigc::cli::run_check_command});
    if (verb.name == "version") {
      out.push_back({verb.name, verb.summary, rigc::cli::run_version_command});
    }
  }
  return out;
}

}  // namespace

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
  const int code = rigc::cli::dispatch(std::vector<std::string>(argv, argv + argc), core_commands(),
                                       run_in_rigc_all);
  return rigc::cli::finish_standard_output(code);
}
