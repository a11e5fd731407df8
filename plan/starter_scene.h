// `rigc new MODEL`: a commented scene for a model file that checks clean and reconstructs. The
// camera stands where the object fills about 60 % of the frame, the aperture keeps its depth
// sharp, two softboxes light it, the exposure is what `check`'s own advice works out for them,
// and the shots are the planner's for the target (docs/commands.md).
#pragma once

#include <optional>
#include <ostream>
#include <string>

#include "compiler/diagnostics.h"

namespace rigc::plan {

struct StarterOptions {
  std::string model_path;
  std::string output_path;  // the scene's file: the model's path is written relative to it
  std::string body = "canon-6d";
  double focal_length_m = 0.05;
  std::optional<double> height_m;  // the object's height; else the model file's own, in metres
  double target = 0.9;             // the share of the surface the planned shots reconstruct
  double visibility_scale = 0;     // of the analyses (0: the planner's default)
};

// The scene's text; nullopt with `error` (or the compiler's diagnostics in `diag`) when the
// model does not load, is implausibly sized without --height, or the plan fails. `log` gets a
// line for each choice.
std::optional<std::string> starter_scene_text(const StarterOptions& options, DiagnosticEngine& diag,
                                              std::ostream& log, std::string* error);

}  // namespace rigc::plan
