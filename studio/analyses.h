// The studio's analyses of the scene as it changes: the coverage of its shots and the capture
// advice `rigc check` gives, each kept between requests so that a capture (a shot added) or its
// undo (one taken back) only analyses the difference. An analysis belongs to a generation: a
// change other than in the shots starts the next one, and older analyses stop at their next shot.
// Background analyses yield to the live view between shots.
#pragma once

#include <atomic>
#include <cstddef>
#include <deque>
#include <filesystem>
#include <functional>
#include <memory>
#include <mutex>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <utility>

#include "analysis/coverage.h"
#include "ir/ir.h"
#include "scene/studio_scene.h"
#include "studio/live_view.h"

namespace rigc::studio {

// What an analysis reads: the scene, its studio, the generation it belongs to and its cache key
// (the scene text without its shots).
struct AnalysedScene {
  std::shared_ptr<const ir::Scene> scene;
  std::shared_ptr<const scene::StudioScene> studio;
  int generation = 0;
  std::string key;
};

class Analyses {
 public:
  // Background analyses wait while `live_view` is busy.
  explicit Analyses(const LiveView& live_view) : live_view_(live_view) {}

  int generation() const { return generation_; }
  // The scene changed other than in its shots: analyses under way stop.
  void next_generation() { ++generation_; }

  // The coverage `rigc coverage` computes (its default options), as the page shows it. A
  // capture's (not `background`) goes first: background analyses stop yielding to the live view
  // while it waits. Nullopt when the scene changed meanwhile.
  std::optional<nlohmann::json> coverage(const AnalysedScene& what, bool background);
  // The warnings `rigc check` prints for `file`, at a reduced resolution. `current_text` gives
  // the scene's text if `what.scene` is still the session's scene, else "" (then nothing is
  // kept). Nullopt when the scene changed meanwhile.
  std::optional<nlohmann::json> advice(const AnalysedScene& what,
                                       const std::function<std::string()>& current_text,
                                       const std::filesystem::path& file);
  // Held by the advice and by whoever else must not run beside it (the shot planner).
  std::mutex& advice_mutex() { return advice_mutex_; }

 private:
  // A coverage analysis kept between requests: shots added or taken back reuse it.
  struct KeptAnalysis {
    std::string key;  // the scene text without its shots
    std::unique_ptr<analysis::IncrementalCoverage> run;
  };
  // Analyses kept for the last scenes (a setting turned back and forth).
  static constexpr std::size_t kKeptAnalyses = 3;

  KeptAnalysis& kept_for(std::deque<KeptAnalysis>& kept, const AnalysedScene& what);
  std::optional<analysis::CoverageResult> analyse(std::deque<KeptAnalysis>& kept,
                                                  const AnalysedScene& what,
                                                  const analysis::CoverageOptions& options,
                                                  bool background);

  const LiveView& live_view_;
  std::atomic<int> generation_{0};
  std::atomic<int> urgent_requests_{0};  // captures waiting for their coverage
  // One coverage and one advice analysis at a time, beside each other.
  std::mutex coverage_mutex_, advice_mutex_;
  std::deque<KeptAnalysis> coverage_kept_;  // under coverage_mutex_, newest first
  std::deque<KeptAnalysis> advice_kept_;    // under advice_mutex_, newest first
  // Shots' sights, shared by both analyses: a new exposure re-judges the faces without rendering
  // their visibility again.
  const std::shared_ptr<analysis::VisibilityCache> visibility_cache_ =
      std::make_shared<analysis::VisibilityCache>();
  // The advice given for the last scene texts (a setting turned back and forth), newest first.
  std::deque<std::pair<std::string, nlohmann::json>> advice_given_;  // under advice_mutex_
};

}  // namespace rigc::studio
