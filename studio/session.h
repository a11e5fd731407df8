// One studio session: the scene file's text as the user is changing it (studio/scene_document.h),
// its compiled IR and renderable studio, the camera the user moves, and the captures; the live
// view (studio/live_view.h) and the analyses (studio/analyses.h) work on what it compiled. Every
// change is an edit of the scene TEXT at the changed value's source span followed by a compile,
// so that out-of-range values are refused with the compiler's own message and the last good
// scene stays.
#pragma once

#include <Eigen/Core>
#include <filesystem>
#include <memory>
#include <mutex>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "compiler/scene_text.h"
#include "ir/ir.h"
#include "scene/studio_scene.h"
#include "studio/analyses.h"
#include "studio/live_view.h"
#include "studio/reference_check.h"
#include "studio/scene_document.h"

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

  // The current view through the live view (the preview and the DSLR model); `scale` of the
  // sensor. A `draft` point-samples the surface (the frames while the camera or a slider moves).
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

  Outcome apply_text(const std::string& text, Change change);
  Outcome push_text(const std::string& text, Change change);
  Outcome compile_view(const View& view);
  static ir::Shot as_view_shot(ir::Shot shot);
  std::shared_ptr<const ir::Scene> view_scene();
  std::string view_pose_text(const View& view) const;
  AnalysedScene analysed();
  std::string text_snapshot(const std::shared_ptr<const ir::Scene>& scene);

  std::mutex mutex_;  // over everything below but the three parts' own state
  SceneDocument document_;
  std::shared_ptr<const ir::Scene> scene_;  // the document's text compiled, with every shot
  std::shared_ptr<const scene::StudioScene> studio_;
  std::optional<ir::Shot> view_shot_;  // the view, compiled as the only shot of the text
  View view_;
  int captures_ = 0;
  int revision_ = 0;  // counts the changes, so the page knows when to refresh
  LiveView live_view_;
  Analyses analyses_{live_view_};
  std::unique_ptr<ReferenceCheck> reference_;
};

}  // namespace rigc::studio
