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
  std::vector<int> station;       // per candidate: poses of one station are captured together
  std::vector<double> angle_deg;  // per candidate: the order within a station
  std::vector<double> station_elevation_rad;  // per station: lower rings are captured first
  double cos_min_triangulation = 1;  // a face needs two usable views at least this far apart
};

struct PlanOptions {
  double target = 0.95;      // share of the whole surface, reconstructable
  int max_shots = 0;         // 0: no limit
  double min_overlap = 0.6;  // share of a shot's seen surface the shot before it saw
};

struct PlannedShot {
  int candidate = 0;
  double gain = 0;             // reconstructable share this shot adds, in capture order
  double reconstructable = 0;  // share after it
  double overlap_with_previous = 0;
};

struct Plan {
  std::vector<PlannedShot> shots;  // in capture order
  double reconstructable = 0;      // share of the surface the plan makes reconstructable
  double reachable = 0;            // share that all candidates together make reconstructable
  bool target_reached = false;
  // Shots whose overlap with the one before stays under min_overlap (no candidate bridges them).
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
