// The search: which candidates, in which order, reach the target share of reconstructable surface
// with the fewest shots while each shot overlaps the one before it.
#pragma once

#include <cstdint>
#include <vector>

#include "analysis/coverage.h"

namespace rigc::plan {

struct PlanProblem {
  // The coverage of every candidate, with sights (CoverageOptions::keep_sights).
  const analysis::CoverageResult* coverage = nullptr;
  // Candidates [0, kept) are shots already taken (the scene's own, kept): every plan starts with
  // them, in their order.
  int kept = 0;
  std::vector<int> station;       // per candidate (-1 for kept shots): captured together
  std::vector<double> angle_deg;  // per candidate: the order within a station
  std::vector<double> station_elevation_rad;  // per station: lower rings are captured first
  Eigen::Vector3d object_center = Eigen::Vector3d::Zero();  // object frame: where steps are seen
  double cos_min_triangulation = 1;  // a face needs two usable views at least this far apart
};

struct PlanOptions {
  double target = 0.95;      // share of the whole surface, reconstructable
  int max_shots = 0;         // 0: no limit
  double min_overlap = 0.6;  // share of a shot's seen surface the shot before it saw
  // The widest angle between neighbouring shots, seen from the object's centre, at which feature
  // matching still chains them.
  double max_step_rad = 0.5235987755982988;  // 30 deg
  // What a face's first usable view is worth in the search against making it reconstructable
  // (1). Half: a first view is half of what a face needs. Near 0: reconstructable area first.
  double first_view_weight = 0.5;
};

struct PlannedShot {
  int candidate = 0;           // < PlanProblem::kept: a kept shot
  double gain = 0;             // reconstructable share this shot adds, in capture order
  double reconstructable = 0;  // share after it
  double overlap_with_previous = 0;
  double step_rad = 0;  // angle to the shot before, seen from the object's centre
};

struct Plan {
  std::vector<PlannedShot> shots;  // in capture order
  double reconstructable = 0;      // share of the surface the plan makes reconstructable
  double reachable = 0;            // share that all candidates together make reconstructable
  bool target_reached = false;
  // Shots that overlap the one before less than min_overlap, or stand more than max_step from it
  // (no candidate bridges them).
  std::vector<int> weak_links;
  std::vector<std::uint8_t> face_reconstructable;  // by the plan
  long gain_evaluations = 0;                       // the search's work, for benchmarks
};

// Lazy greedy next-best-view on the candidates, then the capture order (ring by ring, around the
// turntable), shots inserted where neighbours overlap too little, and shots removed that the
// target does not need.
Plan plan_capture(const PlanProblem& problem, const PlanOptions& options);

// The share of the surface a set of candidates makes reconstructable.
double reconstructable_share(const PlanProblem& problem, const std::vector<int>& shots,
                             std::vector<std::uint8_t>* faces = nullptr);

// The share of candidate `later`'s seen surface that candidate `earlier` saw too.
double overlap_share(const PlanProblem& problem, int earlier, int later);

}  // namespace rigc::plan
