// `rigc plan` from a scene file to the planned scene's text: candidates, their coverage, the
// search.
#pragma once

#include <memory>
#include <optional>
#include <string>

#include "analysis/coverage.h"
#include "compiler/diagnostics.h"
#include "ir/ir.h"
#include "plan/candidates.h"
#include "plan/planner.h"

namespace rigc::plan {

struct PlanRequest {
  std::string scene_path;
  std::string output_path;  // the planned scene's file: its folder resolves relative mesh paths
  CandidateOptions candidates;
  double target = 0.95;
  int max_shots = 0;
  double visibility_scale = 0;  // of the coverage analysis (0: about 1400 px across)
};

struct PlanOutcome {
  ir::Scene scene;                    // as given
  analysis::CoverageResult coverage;  // of the scene's own shots
  CandidateSet candidates;
  analysis::CoverageResult candidate_coverage;  // of every candidate, with sights
  PlanProblem problem;
  PlanOptions options;
  Plan plan;
  std::string planned_text;  // the scene file with the plan as its shots
  double candidate_seconds = 0, search_seconds = 0;
};

// Plans the scene at `request.scene_path`. A scene that does not compile is reported to `diag`;
// other failures set `error`. Either way nullptr.
std::unique_ptr<PlanOutcome> plan_scene(const PlanRequest& request, DiagnosticEngine& diag,
                                        std::string* error);

// The planned scene's `shots:` section: a comment with the plan's figures, then the shots.
std::string planned_shots_section(const PlanOutcome& outcome);

}  // namespace rigc::plan
