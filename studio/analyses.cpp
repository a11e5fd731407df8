#include "studio/analyses.h"

#include <algorithm>
#include <chrono>
#include <sstream>
#include <thread>

#include "analysis/advice.h"
#include "analysis/coverage_output.h"
#include "compiler/diagnostics.h"
#include "io/elapsed.h"

namespace rigc::studio {
namespace {

using Clock = std::chrono::steady_clock;

bool same_shot(const ir::Shot& a, const ir::Shot& b) {
  return a.world_from_camera == b.world_from_camera &&
         a.object_from_camera == b.object_from_camera &&
         a.turntable_angle_rad == b.turntable_angle_rad &&
         a.turntable_velocity_rad_s == b.turntable_velocity_rad_s &&
         a.focus_distance_m == b.focus_distance_m;
}

nlohmann::json coverage_json(const ir::Scene& scene, const analysis::CoverageResult& coverage) {
  std::ostringstream table;
  analysis::print_coverage_table(scene, coverage, table);
  const analysis::ShotCoverage& last = coverage.shots.back();
  return {{"views", coverage.views},
          {"reconstructable_faces", coverage.reconstructable},
          {"table", table.str()},
          {"shots", coverage.shots.size()},
          {"seen_1", last.seen_1},
          {"seen_2", last.seen_2},
          {"reconstructable", last.reconstructable},
          {"new", last.new_area_m2 / coverage.total_area_m2},
          {"overlap", last.overlap_with_previous}};
}

}  // namespace

// The kept analysis of the same scene but for its shots, its shots beyond those `what` begins
// with taken back; a fresh one when there is none.
Analyses::KeptAnalysis& Analyses::kept_for(std::deque<KeptAnalysis>& kept,
                                           const AnalysedScene& what) {
  auto hit = std::find_if(kept.begin(), kept.end(),
                          [&](const KeptAnalysis& k) { return k.key == what.key; });
  if (hit == kept.end()) {
    kept.push_front({what.key, nullptr});
    if (kept.size() > kKeptAnalyses) kept.pop_back();
    hit = kept.begin();
  }
  // Each kept state is a copy of the whole analysis: only the scene in use keeps its undo.
  for (auto& other : kept) {
    if (&other != &*hit && other.run) other.run->forget_undo();
  }
  KeptAnalysis& analysis = *hit;
  if (analysis.run) {
    const auto& shots = what.scene->shots;
    const auto& done = analysis.run->shots();
    std::size_t common = 0;
    while (common < done.size() && common < shots.size() &&
           same_shot(done[common], shots[common])) {
      ++common;
    }
    while (analysis.run && static_cast<std::size_t>(analysis.run->shot_count()) > common) {
      if (!analysis.run->remove_last_shot()) analysis.run.reset();
    }
  }
  return analysis;
}

// The coverage of `what`'s shots with `options`, from a kept analysis where one serves. Nullopt
// when a newer change started another generation meanwhile (the analysis stops at its next shot,
// and is kept for when its scene comes back), or when a capture waits for a background coverage.
std::optional<analysis::CoverageResult> Analyses::analyse(std::deque<KeptAnalysis>& kept,
                                                          const AnalysedScene& what,
                                                          const analysis::CoverageOptions& options,
                                                          bool background) {
  KeptAnalysis& analysis = kept_for(kept, what);
  if (!analysis.run) {
    analysis.run =
        std::make_unique<analysis::IncrementalCoverage>(what.scene, what.studio, options);
  }
  // The live view first: while frames come (a slider or the camera moving), the next shot of a
  // background analysis waits until they pause, unless a capture waits for the coverage.
  const auto live_view_busy = [&] {
    return urgent_requests_ == 0 && live_view_.busy(std::chrono::milliseconds(200));
  };
  const auto& shots = what.scene->shots;
  for (std::size_t s = analysis.run->shot_count(); s < shots.size(); ++s) {
    if (generation_ != what.generation) return std::nullopt;
    // A background analysis hands the kept work to a waiting capture's (it goes on from here).
    if (background && urgent_requests_ > 0 && &kept == &coverage_kept_) return std::nullopt;
    while (background && live_view_busy() && generation_ == what.generation) {
      std::this_thread::sleep_for(std::chrono::milliseconds(5));
    }
    analysis.run->add_shot(shots[s]);
  }
  return analysis.run->result();
}

std::optional<nlohmann::json> Analyses::coverage(const AnalysedScene& what, bool background) {
  struct Urgent {
    std::atomic<int>& count;
    bool on;
    ~Urgent() {
      if (on) --count;
    }
  } urgent{urgent_requests_, !background};
  if (!background) ++urgent_requests_;
  const auto asked = Clock::now();
  std::lock_guard coverage_lock(coverage_mutex_);
  const auto start = Clock::now();
  analysis::CoverageOptions options;
  options.visibility_cache = visibility_cache_;
  const auto result = analyse(coverage_kept_, what, options, background);
  if (!result) return std::nullopt;
  const double ms = io::ms_since(start);
  nlohmann::json out = coverage_json(*what.scene, *result);
  out["wait_ms"] = std::chrono::duration<double, std::milli>(start - asked).count();
  out["analysis_ms"] = ms;
  out["json_ms"] = io::ms_since(start) - ms;
  return out;
}

std::optional<nlohmann::json> Analyses::advice(const AnalysedScene& what,
                                               const std::function<std::string()>& current_text,
                                               const std::filesystem::path& file) {
  const ir::Scene& scene = *what.scene;
  std::lock_guard advice_lock(advice_mutex_);
  const std::string text = current_text();
  for (const auto& [given_for, given] : advice_given_) {
    if (!text.empty() && given_for == text) return given;
  }
  DiagnosticEngine diag;
  diag.add_source(file.string(), text);
  nlohmann::json out = nlohmann::json::array();
  diag.set_handler([&](const Diagnostic& d, const std::string& rendered) {
    out.push_back({{"line", d.loc.line},
                   {"col", d.loc.col},
                   {"severity", d.severity == Severity::kError ? "error" : "warning"},
                   {"message", d.message},
                   {"rendered", rendered}});
  });
  analysis::CoverageOptions options;
  options.visibility_scale = analysis::advice_visibility_scale(scene.camera);
  options.visibility_cache = visibility_cache_;
  const auto coverage = analyse(advice_kept_, what, options, true);
  if (!coverage) return std::nullopt;
  analysis::report_capture_advice(scene, *what.studio, *coverage, diag);
  if (!text.empty()) {
    advice_given_.emplace_front(text, out);
    if (advice_given_.size() > kKeptAnalyses) advice_given_.pop_back();
  }
  return out;
}

}  // namespace rigc::studio
