// One studio session: the scene file's text as the user is changing it, its compiled IR and
// renderable studio, the camera the user moves, and the captures. Every change is an edit of the
// scene TEXT at the changed value's source span followed by a compile, so that out-of-range
// values are refused with the compiler's own message and the last good scene stays.
#pragma once

#include <Eigen/Core>
#include <atomic>
#include <deque>
#include <filesystem>
#include <map>
#include <memory>
#include <mutex>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include "analysis/coverage.h"
#include "compiler/scene_text.h"
#include "io/bounded_file.h"
#include "ir/ir.h"
#include "raster/shadow_map_cache.h"
#include "run/backend.h"
#include "scene/studio_scene.h"
#include "studio/frame_encoding.h"
#include "studio/live_develop.h"
#include "studio/reference_check.h"

namespace rigc::studio {

// The camera the user moves: a pose in the world, aimed at a point, with the turntable's angle.
struct View {
  Eigen::Vector3d position = Eigen::Vector3d::Zero();
  Eigen::Vector3d look_at = Eigen::Vector3d::Zero();
  double turntable_rad = 0;
};

// What a request gets back: ok, or a message (with the compiler's diagnostics rendered as
// `file:line:col: error: ...` and the source line) for a 4xx.
struct Outcome {
  bool ok = true;
  std::string message;
  static Outcome fail(std::string message) { return {false, std::move(message)}; }
};

// The shot the planner suggests next (`rigc plan --next`), now the current view.
struct Suggestion {
  double gain = 0;             // share of the surface it makes reconstructable
  double reconstructable = 0;  // share with it and every shot before it
  std::string entry;           // the shot as scene text, as `rigc plan --next` writes it
};

// A developed frame of the current view.
struct Frame {
  std::string jpeg;
  int width = 0, height = 0;
  Histogram histogram;
  double render_ms = 0;                    // render and development
  std::map<std::string, double> stage_ms;  // the renderer's and the DSLR model's stages
  double encode_ms = 0;
  bool reused_render = false;  // the renderer's linear frame was kept from an earlier frame
};

// What a change of the scene text touched, so that what it cannot have changed is kept: the
// prepared studio (object, materials, studio) across camera and shot changes, the view across
// shot changes, the coverage across shot changes (captures and their undo).
enum class Change { kAnything, kCamera, kShots };

class Session {
 public:
  // Compiles the scene file; nullopt with the diagnostics in `error` when it does not compile.
  // Reference renders go to `run_folder` (empty: out/<scene name>/studio).
  static std::unique_ptr<Session> open(const std::filesystem::path& scene_file, std::string* error,
                                       std::filesystem::path run_folder = {});
  ~Session();

  nlohmann::json state();
  // Sets the value at `path` (camera.* or studio.* only) to scene-language text.
  Outcome set_value(const ScenePath& path, const std::string& value);
  // Several values in one change (a lens preset with a focal length it takes), compiled once.
  Outcome set_values(const std::vector<std::pair<ScenePath, std::string>>& values);
  Outcome add_light(const std::string& entry);
  Outcome remove_light(size_t index);
  Outcome set_view(const View& view);
  Outcome capture();
  // Moves the view to the pose that adds the most reconstructable surface to the shots so far.
  Outcome suggest_next_shot(Suggestion* suggestion);
  Outcome undo();
  Outcome save();
  // Re-reads the file when it changed on disk: a good file replaces the scene (and the unsaved
  // changes); a broken one is kept as `file_error` and the last good scene stays.
  void reload_if_changed();

  // The current view through the preview backend and the DSLR model; `scale` of the sensor. A
  // `draft` point-samples the surface (the frames while the camera or a slider moves).
  std::optional<Frame> frame(double scale, bool draft, std::string* error);
  // The coverage of the scene's shots; nullopt when the scene changed (other than in its shots)
  // while it was being analysed.
  std::optional<nlohmann::json> coverage(bool background = true);
  std::optional<nlohmann::json> advice();
  nlohmann::json mesh();
  int sensor_width_px();

  // The reference check of the current view (see reference_check.h), beside the preview's frame
  // of it at the same size.
  Outcome start_reference(const ReferenceRequest& request);
  ReferenceCheck& reference() { return *reference_; }

 private:
  Session() = default;
  // A coverage analysis kept between requests: shots added or taken back reuse it.
  struct AnalysisCache {
    std::string key;  // the scene text without its shots
    std::unique_ptr<analysis::IncrementalCoverage> run;
  };
  // Analyses kept for the last scenes (a setting turned back and forth).
  static constexpr size_t kKeptAnalyses = 3;
  struct Analysed {
    std::shared_ptr<const ir::Scene> scene;
    std::shared_ptr<const scene::StudioScene> studio;
    int generation = 0;
    std::string key;
  };
  Analysed analysed();
  // A linear frame the preview rendered, and what it depends on besides the exposure, focus and
  // white balance (which the DSLR model applies after it).
  struct RenderCache {
    std::shared_ptr<const scene::StudioScene> studio;  // held, so that its address stays unique
    ir::Mat4 world_from_camera;
    double turntable_angle_rad = 0, turntable_velocity_rad_s = 0, shutter_s = 0;
    dslr::RenderGeometry canvas;
    int subframes = 1;
    bool draft = false;
    std::shared_ptr<const run::RenderedShot> rendered;
  };

  Outcome apply_text(std::string text, Change change);
  Outcome push_text(const std::string& text, Change change);
  Outcome compile_view(const View& view);
  static ir::Shot as_view_shot(ir::Shot shot);
  std::shared_ptr<const ir::Scene> view_scene();
  std::string view_pose_text(const View& view) const;
  std::string read_disk(std::string* error, FileIdentity* identity) const;
  std::string changed_on_disk() const;
  nlohmann::json coverage_json(const ir::Scene& scene,
                               const analysis::CoverageResult& coverage) const;
  std::string text_snapshot(const std::shared_ptr<const ir::Scene>& scene);
  std::optional<analysis::CoverageResult> analyse(std::deque<AnalysisCache>& caches,
                                                  const Analysed& what,
                                                  const analysis::CoverageOptions& options,
                                                  bool background);
  bool render_linear(const ir::Scene& scene,
                     const std::shared_ptr<const scene::StudioScene>& studio, const ir::Shot& shot,
                     const run::RenderSettings& settings, bool draft,
                     std::shared_ptr<const run::RenderedShot>* rendered, bool* reused);
  void render_preview(const ir::Scene& scene,
                      const std::shared_ptr<const scene::StudioScene>& studio, const ir::Shot& shot,
                      double scale, bool draft, run::RenderedShot* rendered);

  std::mutex mutex_;
  // One frame at a time; beside it one coverage and one advice analysis (and plan), so that
  // neither analysis holds up the live view or the other.
  std::mutex render_mutex_, analysis_mutex_, coverage_mutex_;
  std::filesystem::path file_;
  std::string disk_text_;  // the file as last read or saved
  // The file read or saved last, and the one file_ led to when the session opened (through a
  // symbolic link, if file_ is one): Save replaces that file and no other.
  FileIdentity disk_identity_;
  std::filesystem::path opened_target_;
  std::string disk_error_;  // why the file could not be read at the last poll
  std::string text_;        // the scene as the user changed it
  struct UndoEntry {
    std::string text;
    Change change;
  };
  // The last kMostUndoSteps changes: an hour of slider turns would otherwise keep every text.
  static constexpr size_t kMostUndoSteps = 500;
  std::deque<UndoEntry> undo_;
  void remember_for_undo(std::string text, Change change);
  std::string file_error_;                  // the file on disk does not compile: its diagnostics
  std::shared_ptr<const ir::Scene> scene_;  // text_ compiled, with every shot
  std::shared_ptr<const scene::StudioScene> studio_;
  std::optional<ir::Shot> view_shot_;  // the view, compiled as the only shot of text_
  View view_;
  int captures_ = 0;
  int revision_ = 0;  // counts the changes, so the page knows when to refresh
  int reloads_ = 0;   // counts the file's changes on disk, which the page did not make
  // Counts the changes that make the coverage analysis start again (all but shot changes); an
  // analysis of an older generation stops at its next shot.
  std::atomic<int> analysis_generation_{0};
  std::atomic<int> frames_rendering_{0};  // the analysis yields to the live view between shots
  std::atomic<std::int64_t> last_frame_end_{0};  // steady clock ticks
  std::atomic<int> urgent_requests_{0};          // captures waiting for their coverage
  std::deque<AnalysisCache> coverage_caches_;    // under coverage_mutex_, newest first
  std::deque<AnalysisCache> advice_caches_;      // under analysis_mutex_, newest first
  // Shots' sights, shared by both analyses: a new exposure re-judges the faces without rendering
  // their visibility again.
  const std::shared_ptr<analysis::VisibilityCache> visibility_cache_ =
      std::make_shared<analysis::VisibilityCache>();
  // The advice given for the last scene texts (a setting turned back and forth), newest first.
  std::deque<std::pair<std::string, nlohmann::json>> advice_given_;  // under analysis_mutex_
  std::deque<RenderCache> render_cache_;  // under render_mutex_, newest first
  LiveDevelop live_develop_;              // under render_mutex_
  // Shadow maps of shadow_studio_'s lights, kept while the camera moves (under render_mutex_).
  std::shared_ptr<const scene::StudioScene> shadow_studio_;
  std::unique_ptr<raster::ShadowMapCache> shadow_cache_;
  std::unique_ptr<ReferenceCheck> reference_;
};

}  // namespace rigc::studio
