// The plan as a person reads it: each shot's gain, the plan against the scene's own shots, and
// what stays unseen when the target cannot be reached.
#pragma once

#include <iosfwd>
#include <string>

#include "plan/plan_scene.h"

namespace rigc::plan {

// Shares of the surface (of the whole area) that all the candidates together leave
// unreconstructable, by why.
struct UnreachableSurface {
  double resting = 0;       // lies on the turntable: no camera sees it
  double hidden_top = 0;    // no candidate sees it, facing up
  double hidden_side = 0;   // no candidate sees it, facing sideways (concavities, occlusion)
  double hidden_under = 0;  // no candidate sees it, facing down
  double unusable = 0;      // seen, but no view SfM can use (focus, exposure, angle, resolution)
  double one_view = 0;      // one usable view, or views too close to triangulate
};

UnreachableSurface unreachable_surface(const PlanOutcome& outcome);

// The per-shot table, the comparison with the scene's shots and, if the target is missed, why and
// what would reach it.
void print_plan_report(const PlanOutcome& outcome, std::ostream& out);

}  // namespace rigc::plan
