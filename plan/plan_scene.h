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
  std::string scene_text;         // the scene's text when not the file's (named by scene_path)
  bool keep_scene_shots = false;  // plan shots to add to the scene's own
  bool next_shot_only = false;    // with keep_scene_shots: the one shot that adds most
  std::string output_path;  // the planned scene's file: its folder resolves relative mesh paths
  CandidateOptions candidates;
  double target = 0.95;
  int max_shots = 0;
  double max_step_rad = PlanOptions{}.max_step_rad;
  double visibility_scale = 0;  // of the coverage analysis (0: about 1400 px across)
};

struct PlanOutcome {
  ir::Scene scene;                    // as given
  analysis::CoverageResult coverage;  // of the scene's own shots
  CandidateSet candidates;
  analysis::CoverageResult candidate_coverage;  // of every candidate, with sights
  std::vector<ir::Shot> candidate_shots;        // as compiled: kept shots first, then candidates
  PlanProblem problem;
  PlanOptions options;
  Plan plan;
  int kept = 0;                 // the scene's own shots, first in the plan when kept
  bool next_shot_only = false;  // the plan adds the one shot that adds most
  std::string planned_text;     // the scene file with the plan as its shots
  double candidate_seconds = 0, search_seconds = 0;
};

// Plans the scene at `request.scene_path`. A scene that does not compile is reported to `diag`;
// other failures set `error`. Either way nullptr.
std::unique_ptr<PlanOutcome> plan_scene(const PlanRequest& request, DiagnosticEngine& diag,
                                        std::string* error);

// The candidate a planned shot is (nullptr for the scene's own shots, when kept).
const Candidate* planned_candidate(const PlanOutcome& outcome, const PlannedShot& shot);

// The planned shots as scene text: a comment with the plan's figures, then the entries; with the
// `shots:` key unless the scene's own shots are kept (then only the added entries).
std::string planned_shots_text(const PlanOutcome& outcome);

}  // namespace rigc::plan
