#include "plan/report.h"

#include <fmt/format.h>

#include <ostream>

namespace rigc::plan {
namespace {

double percent(double share) {
  return share * 100;
}

void print_shots(const PlanOutcome& outcome, std::ostream& out) {
  out << fmt::format("{:<9} {:<46} {:>8} {:>7} {:>8} {:>8}\n", "shot", "station", "angle", "gain %",
                     "recon %", "overlap");
  for (size_t i = 0; i < outcome.plan.shots.size(); ++i) {
    const PlannedShot& shot = outcome.plan.shots[i];
    const Candidate* candidate = planned_candidate(outcome, shot);
    const Station* station = candidate ? &outcome.candidates.stations[candidate->station] : nullptr;
    const std::string where = station ? describe_station(*station)
                                      : fmt::format("the scene's {}", outcome.scene.shots[i].name);
    const std::string angle = !station || station->kind == StationKind::kPose
                                  ? ""
                                  : fmt::format("{:g}°", candidate->angle_deg);
    const std::string overlap =
        i == 0 ? "" : fmt::format("{:.0f} %", percent(shot.overlap_with_previous));
    const std::string step = i == 0 ? "" : fmt::format("{:.0f}°", shot.step_rad / kDegree);
    out << fmt::format("shot_{:03d} {:<46} {:>8} {:>7.1f} {:>8.1f} {:>8} {:>6}\n", i, where, angle,
                       percent(shot.gain), percent(shot.reconstructable), overlap, step);
  }
}

void print_summary(const PlanOutcome& outcome, std::ostream& out) {
  const Plan& plan = outcome.plan;
  const double scene_share =
      outcome.coverage.shots.empty() ? 0 : outcome.coverage.shots.back().reconstructable;
  out << fmt::format(
      "the scene's {} shots reach {:.1f} %; the plan reaches {:.1f} % with {} "
      "(target {:.1f} %; {} candidate poses reach {:.1f} % together)\n",
      outcome.scene.shots.size(), percent(scene_share), percent(plan.reconstructable),
      plan.shots.size(), percent(outcome.options.target), outcome.candidates.candidates.size(),
      percent(plan.reachable));
  out << fmt::format("candidates' coverage {:.1f} s, search {:.1f} s\n", outcome.candidate_seconds,
                     outcome.search_seconds);
  for (const int i : plan.weak_links) {
    out << fmt::format(
        "note: shot_{:03d} overlaps the shot before it by {:.0f} % only (min_overlap "
        "{:.0f} %); no candidate pose bridges them\n",
        i, percent(plan.shots[i].overlap_with_previous), percent(outcome.options.min_overlap));
  }
}

// Why the target is missed and what would reach it.
void print_unreachable(const PlanOutcome& outcome, std::ostream& out) {
  const Plan& plan = outcome.plan;
  if (plan.reachable >= outcome.options.target) {
    out << fmt::format(
        "the target needs more than the {} shots --max-shots allows: all the "
        "candidates reach {:.1f} %\n",
        outcome.options.max_shots, percent(plan.reachable));
    return;
  }
  const UnreachableSurface u = unreachable_surface(outcome);
  out << fmt::format(
      "the target {:.1f} % cannot be reached from these candidate poses; what "
      "stays unreconstructable, as shares of the surface:\n",
      percent(outcome.options.target));
  auto line = [&](double share, const std::string& what, const std::string& fix) {
    if (share < 0.0005) return;
    out << fmt::format("  {:5.1f} % {}: {}\n", percent(share), what, fix);
  };
  line(u.resting, "rests on the turntable",
       "no camera sees it; turn the object over for a second session");
  line(u.hidden_top, "faces up, seen by no candidate", "add a higher ring (--rings ...,80)");
  line(u.hidden_side, "faces sideways, seen by no candidate (concavities or occlusion)",
       "add rings at other heights or closer distances (--rings, --distances)");
  line(u.hidden_under, "faces down, seen by no candidate",
       "add a low ring (--rings -10,...) or turn the object over for a second session");
  line(u.unusable, "seen, but never in a view SfM can use",
       "`rigc coverage` on the planned scene tells focus, exposure, angle or resolution apart");
  line(u.one_view, "has one usable view only, or views too close together",
       "a finer --azimuth-step or more rings");
}

}  // namespace

UnreachableSurface unreachable_surface(const PlanOutcome& outcome) {
  const analysis::CoverageResult& c = outcome.candidate_coverage;
  UnreachableSurface u;
  const double total = std::max(c.total_area_m2, 1e-30);
  for (size_t f = 0; f < c.face_area_m2.size(); ++f) {
    if (c.reconstructable[f]) continue;
    const double share = c.face_area_m2[f] / total;
    const double up = c.face_normal[f].z();
    if (c.resting[f]) {
      u.resting += share;
    } else if (c.views[f] == 0) {
      (up > 0.5 ? u.hidden_top : up < -0.5 ? u.hidden_under : u.hidden_side) += share;
    } else if (c.usable_views[f] == 0) {
      u.unusable += share;
    } else {
      u.one_view += share;
    }
  }
  return u;
}

void print_plan_report(const PlanOutcome& outcome, std::ostream& out) {
  print_shots(outcome, out);
  const bool added = static_cast<int>(outcome.plan.shots.size()) > outcome.kept;
  if (outcome.next_shot_only) {
    out << (added ? "the next shot:\n" + planned_shots_text(outcome)
                  : std::string("no candidate pose adds to the scene's shots\n"));
    return;
  }
  if (outcome.kept > 0 && added) out << "added shots:\n" << planned_shots_text(outcome);
  print_summary(outcome, out);
  if (!outcome.plan.target_reached) print_unreachable(outcome, out);
}

}  // namespace rigc::plan
