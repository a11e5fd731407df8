// The verbs of `rigc`, COLMAP-style: `rigc <verb> [options]`, each verb with its own options.
#pragma once

#include <functional>
#include <string>
#include <vector>

namespace rigc::cli {

// Exit codes of every verb.
constexpr int kExitOk = 0;
constexpr int kExitUserError = 1;      // bad scene, bad option: diagnostics say why
constexpr int kExitInternalError = 2;  // a bug, or an external tool that failed

struct Command {
  std::string name;
  std::string summary;
  // Receives the verb's own arguments (argv[0] is "rigc <verb>").
  std::function<int(std::vector<std::string> args)> run;
};

// The dispatch table. Backends and analyses add their verbs here.
const std::vector<Command>& commands();

// Runs `rigc` with its full argument list; returns the exit code.
int run_main(std::vector<std::string> args);

}  // namespace rigc::cli
