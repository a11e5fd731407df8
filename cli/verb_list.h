// The verbs of `rigc` by name, with a line on each: what both binaries print in their usage.
#pragma once

#include <string>
#include <vector>

namespace rigc::cli {

struct VerbSummary {
  std::string name;
  std::string summary;
  std::string task;  // the heading the usage lists it under
};

// Every verb, in the order the usage lists them (grouped by task).
const std::vector<VerbSummary>& verb_summaries();

// "usage: rigc <command> [options]" and the verbs, one a line, under their tasks, with an
// example to start from.
std::string usage_text();

}  // namespace rigc::cli
