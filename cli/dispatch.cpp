#include "cli/dispatch.h"

#include <fmt/format.h>

#include <algorithm>
#include <filesystem>
#include <iostream>
#include <regex>

#include "cli/verb_list.h"
#include "cli/verbs.h"
#include "compiler/diagnostics.h"

namespace rigc::cli {

namespace fs = std::filesystem;

std::vector<Command> table_of(
    const std::map<std::string, std::function<int(std::vector<std::string>)>>& runs) {
  std::vector<Command> out;
  for (const VerbSummary& verb : verb_summaries()) {
    const auto run = runs.find(verb.name);
    if (run != runs.end()) out.push_back({verb.name, verb.summary, run->second});
  }
  return out;
}

int dispatch(std::vector<std::string> args, const std::vector<Command>& table,
             const OtherVerbs& other_verbs) {
  if (args.size() < 2) {
    std::cerr << usage_text();
    return kExitUserError;
  }
  const std::string verb = args[1];
  if (verb == "-h" || verb == "--help" || verb == "help") {
    std::cout << usage_text();
    return kExitOk;
  }
  if (verb == "--version") return run_version_command({"rigc version"});
  for (const auto& command : table) {
    if (command.name != verb) continue;
    std::vector<std::string> verb_args = {"rigc " + verb};
    verb_args.insert(verb_args.end(), args.begin() + 2, args.end());
    try {
      return command.run(verb_args);
    } catch (const fs::filesystem_error& e) {
      // A path the user gave that cannot be followed (a symbolic link loop, no permission):
      // their files, not a bug.
      std::cerr << fmt::format("rigc: error: cannot use '{}': {}\n", e.path1().string(),
                               e.code().message());
      return kExitUserError;
    } catch (const std::exception& e) {
      // Libraries colour their messages (Open3D's errors come as "\e[1;31m[Open3D Error] ...");
      // the terminal codes are dropped.
      const std::string what = std::regex_replace(e.what(), std::regex("\x1b\\[[0-9;]*m"), "");
      std::cerr << "rigc: internal error: " << what << '\n';
      return kExitInternalError;
    }
  }
  std::vector<std::string> names;
  for (const VerbSummary& v : verb_summaries()) names.push_back(v.name);
  if (other_verbs && std::find(names.begin(), names.end(), verb) != names.end()) {
    return other_verbs(args);
  }
  std::string suggestion = closest_match(verb, names);
  std::cerr << fmt::format(
      "rigc: error: unknown command '{}'{}\n\n{}", verb,
      suggestion.empty() ? "" : fmt::format("; did you mean '{}'?", suggestion), usage_text());
  return kExitUserError;
}

}  // namespace rigc::cli
