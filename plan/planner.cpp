#include "plan/planner.h"

#include <tbb/blocked_range.h>
#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <numeric>
#include <queue>
#include <span>
#include <utility>

namespace rigc::plan {
namespace {

using Eigen::Vector3d;

// The faces' state under a growing set of shots: the usable views of each, and whether two of
// them triangulate it.
class SurfaceState {
 public:
  SurfaceState(const PlanProblem& problem, double first_view_weight = 0.5)
      : problem_(problem),
        first_view_weight_(first_view_weight),
        coverage_(*problem.coverage),
        views_(coverage_.face_area_m2.size()),
        reconstructable_(coverage_.face_area_m2.size(), 0) {}

  // What adding candidate `c` is worth (m²) when a reconstructable face counts 1 and a face with a
  // usable view `first_view_weight`.
  double gain(int c) const {
    double value = 0;
    const Vector3d& eye = coverage_.sights[c].eye;
    for (const std::uint32_t f : coverage_.sights[c].usable) {
      if (reconstructable_[f]) continue;
      if (views_[f].empty()) {
        value += first_view_weight_ * coverage_.face_area_m2[f];
      } else if (triangulates(eye, f)) {
        value += (1 - first_view_weight_) * coverage_.face_area_m2[f];
      }
    }
    return value;
  }

  void add(int c) {
    const Vector3d& eye = coverage_.sights[c].eye;
    for (const std::uint32_t f : coverage_.sights[c].usable) {
      if (!reconstructable_[f] && !views_[f].empty() && triangulates(eye, f)) {
        reconstructable_[f] = 1;
        reconstructable_area_ += coverage_.face_area_m2[f];
      }
      views_[f].push_back(c);
    }
  }

  double share() const { return reconstructable_area_ / std::max(coverage_.total_area_m2, 1e-30); }
  const std::vector<std::uint8_t>& faces() const { return reconstructable_; }

 private:
  // Whether a view from `eye` and one of the face's views are at least the triangulation angle
  // apart.
  bool triangulates(const Vector3d& eye, std::uint32_t f) const {
    const Vector3d& center = coverage_.face_center[f];
    const Vector3d ray = (eye - center).normalized();
    for (const int v : views_[f]) {
      const Vector3d other = (coverage_.sights[v].eye - center).normalized();
      if (ray.dot(other) <= problem_.cos_min_triangulation) return true;
    }
    return false;
  }

  const PlanProblem& problem_;
  const double first_view_weight_;
  const analysis::CoverageResult& coverage_;
  std::vector<std::vector<int>> views_;
  std::vector<std::uint8_t> reconstructable_;
  double reconstructable_area_ = 0;
};

// The share of candidate `later`'s seen surface that `earlier` saw; `marks` is all zero, per face,
// and is left so.
double overlap_marked(const PlanProblem& problem, int earlier, int later,
                      std::vector<std::uint8_t>& marks) {
  const analysis::CoverageResult& coverage = *problem.coverage;
  for (const std::uint32_t f : coverage.sights[earlier].seen) marks[f] = 1;
  double shared = 0, visible = 0;
  for (const std::uint32_t f : coverage.sights[later].seen) {
    visible += coverage.face_area_m2[f];
    if (marks[f]) shared += coverage.face_area_m2[f];
  }
  for (const std::uint32_t f : coverage.sights[earlier].seen) marks[f] = 0;
  return visible > 0 ? shared / visible : 0;
}

// The share of the surface that the coverage's shots together make reconstructable.
double reachable_share(const analysis::CoverageResult& coverage) {
  double area = 0;
  for (size_t f = 0; f < coverage.face_area_m2.size(); ++f) {
    if (coverage.reconstructable[f]) area += coverage.face_area_m2[f];
  }
  return area / std::max(coverage.total_area_m2, 1e-30);
}

constexpr double kShortOfReachable = 0.005;

class Planner {
 public:
  Planner(const PlanProblem& problem, const PlanOptions& options)
      : problem_(problem),
        options_(options),
        candidate_count_(static_cast<int>(problem.coverage->sights.size())),
        scratch_(problem.coverage->face_area_m2.size(), 0) {}

  Plan run() {
    // Short of an unreachable target, the plan stops near what the candidates can reach instead
    // of adding shots for slivers.
    goal_ = std::min(options_.target, reachable_share(*problem_.coverage) - kShortOfReachable);
    std::vector<int> order(problem_.kept);
    std::iota(order.begin(), order.end(), 0);
    const std::vector<int> added = capture_order(choose_greedily());
    order.insert(order.end(), added.begin(), added.end());
    bridge_weak_links(order);
    prune(order);
    return summarise(order);
  }

 private:
  std::vector<int> choose_greedily();
  std::vector<int> capture_order(std::vector<int> chosen) const;
  void bridge_weak_links(std::vector<int>& order);
  int best_bridge(int before, int after, const std::vector<int>& order) const;
  void prune(std::vector<int>& order) const;
  std::vector<double> losses(const std::vector<int>& order) const;
  std::array<int, 2> critical_views(const std::vector<Vector3d>& rays) const;
  bool can_remove(const std::vector<int>& order, size_t i) const;
  Plan summarise(const std::vector<int>& order) const;
  bool full(const std::vector<int>& order) const {
    return options_.max_shots > 0 && static_cast<int>(order.size()) >= options_.max_shots;
  }
  double overlap(int earlier, int later) const;
  double step(int a, int b) const;
  double link(int earlier, int later) const;

  const PlanProblem& problem_;
  const PlanOptions& options_;
  const int candidate_count_;
  double goal_ = 0;
  mutable std::vector<std::uint8_t> scratch_;  // per face, for overlaps
  long evaluations_ = 0;
};

// Lazy greedy: a candidate's last gain bounds its next one (nearly: a new view can let a face
// triangulate with a candidate that it could not before), so only the best stale entry is
// re-evaluated each round.
std::vector<int> Planner::choose_greedily() {
  SurfaceState state(problem_, options_.first_view_weight);
  using Entry = std::pair<double, int>;
  std::priority_queue<Entry> heap;
  for (int c = 0; c < problem_.kept; ++c) state.add(c);
  for (int c = problem_.kept; c < candidate_count_; ++c) heap.push({state.gain(c), c});
  evaluations_ += candidate_count_ - problem_.kept;
  std::vector<int> chosen;
  auto room = [&] {
    return options_.max_shots == 0 ||
           problem_.kept + static_cast<int>(chosen.size()) < options_.max_shots;
  };
  while (state.share() < goal_ && room() && !heap.empty()) {
    const int c = heap.top().second;
    heap.pop();
    const double gain = state.gain(c);
    ++evaluations_;
    if (!heap.empty() && gain < heap.top().first) {
      heap.push({gain, c});
      continue;
    }
    if (gain <= 0) break;
    state.add(c);
    chosen.push_back(c);
  }
  return chosen;
}

// Ring by ring from the lowest, each ring around the turntable from the end of its widest gap, so
// that consecutive shots are neighbours.
std::vector<int> Planner::capture_order(std::vector<int> chosen) const {
  std::stable_sort(chosen.begin(), chosen.end(), [&](int a, int b) {
    const int sa = problem_.station[a], sb = problem_.station[b];
    if (sa != sb) {
      const double ea = problem_.station_elevation_rad[sa], eb = problem_.station_elevation_rad[sb];
      return ea != eb ? ea < eb : sa < sb;
    }
    return problem_.angle_deg[a] < problem_.angle_deg[b];
  });
  for (size_t begin = 0; begin < chosen.size();) {
    size_t end = begin + 1;
    while (end < chosen.size() &&
           problem_.station[chosen[end]] == problem_.station[chosen[begin]]) {
      ++end;
    }
    size_t widest_gap_end = begin;
    double widest = -1;
    for (size_t i = begin; i < end; ++i) {
      const double previous = problem_.angle_deg[chosen[i == begin ? end - 1 : i - 1]];
      double gap = problem_.angle_deg[chosen[i]] - previous;
      if (gap <= 0) gap += 360;
      if (gap > widest) widest = gap, widest_gap_end = i;
    }
    std::rotate(chosen.begin() + begin, chosen.begin() + widest_gap_end, chosen.begin() + end);
    begin = end;
  }
  return chosen;
}

double Planner::overlap(int earlier, int later) const {
  return overlap_marked(problem_, earlier, later, scratch_);
}

double Planner::step(int a, int b) const {
  const auto& sights = problem_.coverage->sights;
  const Vector3d from_a = sights[a].eye - problem_.object_center;
  const Vector3d from_b = sights[b].eye - problem_.object_center;
  return std::acos(std::clamp(from_a.normalized().dot(from_b.normalized()), -1.0, 1.0));
}

// How well `later` chains to `earlier`: 1 or more when they overlap at least min_overlap and stand
// at most max_step apart; otherwise the worse of the two ratios.
double Planner::link(int earlier, int later) const {
  const double by_overlap = options_.min_overlap > 0
                                ? overlap(earlier, later) / options_.min_overlap
                                : std::numeric_limits<double>::infinity();
  const double angle = step(earlier, later);
  const double by_step =
      angle > 0 ? options_.max_step_rad / angle : std::numeric_limits<double>::infinity();
  return std::min(by_overlap, by_step);
}

// Between neighbours that do not chain, the candidate that links to both best.
void Planner::bridge_weak_links(std::vector<int>& order) {
  for (size_t i = std::max(1, problem_.kept); i < order.size(); ++i) {
    while (link(order[i - 1], order[i]) < 1 && !full(order)) {
      const int bridge = best_bridge(order[i - 1], order[i], order);
      if (bridge < 0) break;
      order.insert(order.begin() + static_cast<std::ptrdiff_t>(i), bridge);
    }
  }
}

// The candidate whose weaker link with `before` and `after` is best, if better than theirs: from
// `after`'s station when one there links both, so a ring stays one sequence.
int Planner::best_bridge(int before, int after, const std::vector<int>& order) const {
  int best_candidate = -1, best_same_station = -1;
  double best = link(before, after), best_on_station = 1 - 1e-9;
  for (int c = problem_.kept; c < candidate_count_; ++c) {
    if (std::find(order.begin(), order.end(), c) != order.end()) continue;
    // The step bounds the link, and costs nothing next to an overlap.
    const double step_bound =
        options_.max_step_rad / std::max({step(before, c), step(c, after), 1e-12});
    if (step_bound <= std::min(best, best_on_station)) continue;
    const double weaker = std::min(link(before, c), link(c, after));
    if (weaker > best + 1e-9) best = weaker, best_candidate = c;
    if (problem_.station[c] == problem_.station[after] && weaker > best_on_station) {
      best_on_station = weaker, best_same_station = c;
    }
  }
  return best_same_station >= 0 ? best_same_station : best_candidate;
}

// Local search: drop shots the target does not need, the least useful first, as long as their
// neighbours still overlap enough.
void Planner::prune(std::vector<int>& order) const {
  const double needed = std::min(goal_, reconstructable_share(problem_, order));
  for (bool removed = true; removed && order.size() > 1;) {
    removed = false;
    const double share = reconstructable_share(problem_, order);
    const std::vector<double> loss = losses(order);
    std::vector<size_t> by_loss(order.size());
    std::iota(by_loss.begin(), by_loss.end(), 0);
    std::stable_sort(by_loss.begin(), by_loss.end(),
                     [&](size_t a, size_t b) { return loss[a] < loss[b]; });
    for (const size_t i : by_loss) {
      if (share - loss[i] < needed - 1e-12) break;
      if (static_cast<int>(i) < problem_.kept) continue;
      if (!can_remove(order, i)) continue;
      order.erase(order.begin() + static_cast<std::ptrdiff_t>(i));
      removed = true;
      break;
    }
  }
}

// For each shot of `order`, the share of the surface that is reconstructable with it and not
// without it: the faces all of whose triangulating pairs of views include it.
std::vector<double> Planner::losses(const std::vector<int>& order) const {
  const analysis::CoverageResult& coverage = *problem_.coverage;
  const size_t face_count = coverage.face_area_m2.size();
  // The faces' usable views among the shots, as positions in `order` (compressed rows).
  std::vector<std::uint32_t> offsets(face_count + 1, 0);
  for (const int c : order) {
    for (const std::uint32_t f : coverage.sights[c].usable) ++offsets[f + 1];
  }
  for (size_t f = 0; f < face_count; ++f) offsets[f + 1] += offsets[f];
  std::vector<std::uint32_t> views(offsets.back()), next(offsets.begin(), offsets.end() - 1);
  for (size_t i = 0; i < order.size(); ++i) {
    for (const std::uint32_t f : coverage.sights[order[i]].usable) {
      views[next[f]++] = static_cast<std::uint32_t>(i);
    }
  }
  tbb::enumerable_thread_specific<std::vector<double>> partial(
      std::vector<double>(order.size(), 0.0));
  tbb::parallel_for(
      tbb::blocked_range<size_t>(0, face_count, 4096),
      [&](const tbb::blocked_range<size_t>& range) {
        std::vector<double>& loss = partial.local();
        std::vector<Vector3d> rays;
        for (size_t f = range.begin(); f != range.end(); ++f) {
          const std::span<const std::uint32_t> face_views(views.data() + offsets[f],
                                                          offsets[f + 1] - offsets[f]);
          if (face_views.size() < 2) continue;
          rays.clear();
          for (const std::uint32_t i : face_views) {
            rays.push_back((coverage.sights[order[i]].eye - coverage.face_center[f]).normalized());
          }
          for (const int critical : critical_views(rays)) {
            if (critical < 0) continue;
            loss[face_views[critical]] += coverage.face_area_m2[f] / coverage.total_area_m2;
          }
        }
      });
  std::vector<double> loss(order.size(), 0.0);
  for (const std::vector<double>& part : partial) {
    for (size_t i = 0; i < loss.size(); ++i) loss[i] += part[i];
  }
  return loss;
}

// The views (up to two; -1 for none) that every triangulating pair of `rays` includes: a face
// loses its reconstructability to the removal of one of those only.
std::array<int, 2> Planner::critical_views(const std::vector<Vector3d>& rays) const {
  const double cos_min = problem_.cos_min_triangulation;
  auto pair_without = [&](int excluded) {
    for (size_t a = 0; a < rays.size(); ++a) {
      for (size_t b = a + 1; b < rays.size(); ++b) {
        if (static_cast<int>(a) == excluded || static_cast<int>(b) == excluded) continue;
        if (rays[a].dot(rays[b]) <= cos_min) return true;
      }
    }
    return false;
  };
  for (size_t a = 0; a < rays.size(); ++a) {
    for (size_t b = a + 1; b < rays.size(); ++b) {
      if (rays[a].dot(rays[b]) > cos_min) continue;
      // The first pair: only its two views can be in every pair.
      const int first = static_cast<int>(a), second = static_cast<int>(b);
      return {pair_without(first) ? -1 : first, pair_without(second) ? -1 : second};
    }
  }
  return {-1, -1};
}

// Whether the neighbours of shot `i` would still chain (or did not before either).
bool Planner::can_remove(const std::vector<int>& order, size_t i) const {
  if (i == 0 || i + 1 == order.size()) return true;
  const double joined = link(order[i - 1], order[i + 1]);
  return joined >= 1 ||
         joined >= std::min(link(order[i - 1], order[i]), link(order[i], order[i + 1]));
}

Plan Planner::summarise(const std::vector<int>& order) const {
  Plan plan;
  SurfaceState state(problem_);
  for (size_t i = 0; i < order.size(); ++i) {
    PlannedShot shot;
    shot.candidate = order[i];
    const double before = state.share();
    state.add(order[i]);
    shot.reconstructable = state.share();
    shot.gain = shot.reconstructable - before;
    shot.overlap_with_previous = i > 0 ? overlap(order[i - 1], order[i]) : 0;
    shot.step_rad = i > 0 ? step(order[i - 1], order[i]) : 0;
    if (i > 0 && link(order[i - 1], order[i]) < 1) {
      plan.weak_links.push_back(static_cast<int>(i));
    }
    plan.shots.push_back(shot);
  }
  plan.reconstructable = state.share();
  plan.face_reconstructable = state.faces();
  plan.target_reached = plan.reconstructable >= options_.target;
  plan.reachable = reachable_share(*problem_.coverage);
  plan.gain_evaluations = evaluations_;
  return plan;
}

}  // namespace

Plan plan_capture(const PlanProblem& problem, const PlanOptions& options) {
  return Planner(problem, options).run();
}

double reconstructable_share(const PlanProblem& problem, const std::vector<int>& shots,
                             std::vector<std::uint8_t>* faces) {
  SurfaceState state(problem);
  for (const int c : shots) state.add(c);
  if (faces) *faces = state.faces();
  return state.share();
}

double overlap_share(const PlanProblem& problem, int earlier, int later) {
  std::vector<std::uint8_t> marks(problem.coverage->face_area_m2.size(), 0);
  return overlap_marked(problem, earlier, later, marks);
}

}  // namespace rigc::plan
