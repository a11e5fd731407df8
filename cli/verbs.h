// The verbs that live in files of their own; args[0] is "rigc <verb>". Each returns the exit
// code: 0 ok, 1 user error, 2 internal or external-tool failure.
#pragma once

#include <string>
#include <vector>

namespace rigc::cli {

int run_eval_command(std::vector<std::string> args);
int run_compare_command(std::vector<std::string> args);

}  // namespace rigc::cli
