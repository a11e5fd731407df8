// The studio's reference check: the current view rendered by a reference renderer (POV-Ray or
// Cycles) through the backend registry and the run loop, in the background, into the studio's own
// run folder; shown beside the preview's frame of the same view at the same size.
#pragma once

#include <atomic>
#include <chrono>
#include <filesystem>
#include <memory>
#include <mutex>
#include <nlohmann/json.hpp>
#include <string>
#include <thread>

#include "ir/ir.h"

namespace rigc::studio {

struct ReferenceRequest {
  std::string backend = "povray";  // a name from the backend registry other than the preview
  int width = 640;                 // pixels across (the sensor's aspect)
  int samples = 0;                 // the renderer's samples per pixel; 0: its default
};

class ReferenceCheck {
 public:
  // Renders go to `run_root`/<backend> (a run folder, as `rigc render -o` makes it).
  explicit ReferenceCheck(std::filesystem::path run_root);
  ~ReferenceCheck();  // cancels a render in progress and waits for it

  // Starts rendering `view` (a scene whose only shot is the current view) at `scale`; `preview`
  // is the preview's JPEG of the same view at the same scale. False with `error` when a render
  // is in progress or the backend is unknown or not installed.
  bool start(std::shared_ptr<const ir::Scene> view, double scale, std::string preview_jpeg,
             const ReferenceRequest& request, std::string* error);
  // Stops the renderer; the check ends as cancelled.
  void cancel();
  // {state: idle|running|done|failed|cancelled, backend, elapsed_s, progress (0..1 or null),
  //  message, log (the renderer's log file), width, height}
  nlohmann::json status() const;
  // The JPEG of the reference ("reference") or of the preview ("preview") of the last check that
  // finished; empty when there is none.
  std::string image(const std::string& which) const;

 private:
  void render(std::shared_ptr<const ir::Scene> view, double scale, ReferenceRequest request);
  void finish(const std::string& state, const std::string& message);

  std::filesystem::path run_root_;
  mutable std::mutex mutex_;
  std::thread worker_;
  std::atomic<bool> running_{false}, cancelled_{false};
  std::string state_ = "idle", backend_, message_;
  std::filesystem::path log_;  // the shot's renderer log, while and after it renders
  std::chrono::steady_clock::time_point started_;
  double elapsed_s_ = 0;
  std::string preview_jpeg_, pending_preview_, reference_jpeg_;
  int width_ = 0, height_ = 0;
};

// The share of the render done, from the renderer's log (POV-Ray's "Rendered N of M pixels",
// Blender's "Sample N/M"); negative when the log does not say.
double render_progress_from_log(const std::string& log_text);

}  // namespace rigc::studio
