#include "cli/verb_list.h"

#include <fmt/format.h>

namespace rigc::cli {

const std::vector<VerbSummary>& verb_summaries() {
  static const std::vector<VerbSummary> verbs = {
      {"check", "check a scene and report errors and capture warnings"},
      {"compile", "compile a scene to the IR or to a backend's scripts"},
      {"render", "render every shot with a backend (rigc render --help lists them)"},
      {"coverage", "analyse which faces the shots see and what SfM can use"},
      {"eval", "reconstruct a run with COLMAP and measure it against the ground truth"},
      {"compare", "render with several backends and compare reconstruction accuracy"},
      {"plan", "plan the fewest shots that reach a coverage target"},
      {"studio", "the interactive capture studio in a browser"},
      {"sweep", "compare capture configurations: scene variants, locally or on Slurm"},
      {"twin", "make a digital twin of a real capture (cameras, visual hull, photo colours)"},
      {"version", "print the version"},
  };
  return verbs;
}

std::string usage_text() {
  std::string text = "usage: rigc <command> [options]\n\ncommands:\n";
  for (const VerbSummary& verb : verb_summaries()) {
    text += fmt::format("  {:<10} {}\n", verb.name, verb.summary);
  }
  text += "\n`rigc <command> --help` describes a command's options.\n";
  return text;
}

}  // namespace rigc::cli
