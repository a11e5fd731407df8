// The verbs that live in files of their own; args[0] is "rigc <verb>". Each returns the exit
// code: 0 ok, 1 user error, 2 internal or external-tool failure.
#pragma once

#include <CLI/CLI.hpp>
#include <optional>
#include <string>
#include <vector>

#include "eval/eval.h"

namespace rigc::cli {

int run_check_command(std::vector<std::string> args);
int run_version_command(std::vector<std::string> args);
int run_eval_command(std::vector<std::string> args);
int run_compare_command(std::vector<std::string> args);
int run_plan_command(std::vector<std::string> args);
int run_studio_command(std::vector<std::string> args);
int run_sweep_command(std::vector<std::string> args);
int run_twin_command(std::vector<std::string> args);
int run_new_command(std::vector<std::string> args);

// "95%" or "0.95": a share in (0, 1], as --target takes it (plan, new).
std::optional<double> parse_target(const std::string& text);

// --samples N|auto into `samples` (run::parse_samples: a count 0..65536, or auto for
// run::kConvergedSamples); `what` is the option's help.
CLI::Option* add_samples_option(CLI::App& app, int& samples, const std::string& what);

// The reconstruction options `eval` and `compare` share.
void add_eval_options(CLI::App& app, eval::EvalOptions& options);

}  // namespace rigc::cli
