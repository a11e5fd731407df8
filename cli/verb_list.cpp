#include "cli/verb_list.h"

#include <fmt/format.h>

namespace rigc::cli {

const std::vector<VerbSummary>& verb_summaries() {
  static const std::string kScene = "describe and check a rig";
  static const std::string kPhotos = "see its photos";
  static const std::string kCapture = "plan the capture";
  static const std::string kMeasure = "measure what SfM makes of it";
  static const std::string kReal = "real captures";
  static const std::string kOther = "other";
  static const std::vector<VerbSummary> verbs = {
      {"new", "write a commented starting scene for a model file, its shots planned", kScene},
      {"check", "check a scene and report errors and capture warnings", kScene},
      {"compile", "compile a scene to the IR or to a backend's scripts", kScene},
      {"render", "render every shot with a backend (rigc render --help lists them)", kPhotos},
      {"studio", "the interactive capture studio in a browser", kPhotos},
      {"coverage", "analyse which faces the shots see and what SfM can use", kCapture},
      {"plan", "plan the fewest shots that reach a coverage target", kCapture},
      {"eval", "reconstruct a run with COLMAP and measure it against the ground truth", kMeasure},
      {"compare", "render with several backends and compare reconstruction accuracy", kMeasure},
      {"sweep", "compare capture configurations: scene variants, locally or on Slurm", kMeasure},
      {"twin", "make a digital twin of a real capture (cameras, visual hull, photo colours)",
       kReal},
      {"version", "print the version", kOther},
  };
  return verbs;
}

std::string usage_text() {
  std::string text = "usage: rigc <command> [options]\n";
  std::string task;
  for (const VerbSummary& verb : verb_summaries()) {
    if (verb.task != task) text += fmt::format("\n{}:\n", task = verb.task);
    text += fmt::format("  {:<10} {}\n", verb.name, verb.summary);
  }
  text +=
      "\nA start: rigc check scenes/paper-turntable.yaml, then rigc studio on it.\n"
      "`rigc <command> --help` describes a command's options; eval --photos measures real "
      "photos.\n";
  return text;
}

}  // namespace rigc::cli
