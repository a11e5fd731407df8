// Runs one verb of a command table with rigc's exit codes and error handling.
#pragma once

#include <functional>
#include <map>
#include <string>
#include <vector>

#include "cli/commands.h"

namespace rigc::cli {

// The verbs of verb_summaries() that `runs` holds, in the usage's order, with its summaries.
std::vector<Command> table_of(
    const std::map<std::string, std::function<int(std::vector<std::string>)>>& runs);

// Runs a verb of verb_summaries() that `table` does not hold (the whole argument list).
using OtherVerbs = std::function<int(const std::vector<std::string>& args)>;

// `rigc <verb> ...` with `table`'s verbs (usage, --help and --version included); a verb that
// only other_verbs runs goes there, and an unknown one is an error naming the closest verb.
int dispatch(std::vector<std::string> args, const std::vector<Command>& table,
             const OtherVerbs& other_verbs);

}  // namespace rigc::cli
