// The studio's live view: frames of the current view through a backend's live renderer (the
// preview's, found in the registry like every other consumer's backend) and the DSLR model, one
// frame at a time. A linear frame is kept for the next one that differs only in what the DSLR
// model applies (exposure, focus, white balance, noise).
#pragma once

#include <atomic>
#include <chrono>
#include <cstdint>
#include <deque>
#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <string>

#include "ir/ir.h"
#include "run/backend.h"
#include "scene/studio_scene.h"
#include "studio/frame_encoding.h"
#include "studio/live_develop.h"

namespace rigc::studio {

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

class LiveView {
 public:
  // Frames through the live renderer of the backend called `backend` (backends/registry.h).
  explicit LiveView(const std::string& backend = "preview");
  ~LiveView();

  // `shot` of `scene` as `wish` says, developed and encoded as JPEG.
  std::optional<Frame> frame(const ir::Scene& scene,
                             const std::shared_ptr<const scene::StudioScene>& studio,
                             const ir::Shot& shot, run::FrameWish wish, std::string* error);

  // Whether a frame is rendering or one ended less than `quiet` ago: while the user moves
  // something, background work waits.
  bool busy(std::chrono::milliseconds quiet) const;

 private:
  // A linear frame rendered, and what it depends on besides what the DSLR model applies.
  struct RenderedView {
    std::shared_ptr<const scene::StudioScene> studio;  // held, so that its address stays unique
    ir::Mat4 world_from_camera;
    double turntable_angle_rad = 0, turntable_velocity_rad_s = 0, shutter_s = 0;
    dslr::RenderGeometry canvas;
    int subframes = 1;
    bool draft = false;
    std::shared_ptr<const run::RenderedShot> rendered;
    bool same_view(const RenderedView& other) const;
  };
  std::shared_ptr<const run::RenderedShot> render_linear(
      const ir::Scene& scene, const std::shared_ptr<const scene::StudioScene>& studio,
      const ir::Shot& shot, run::FrameWish wish, bool* reused, std::string* error);

  std::unique_ptr<run::LiveRenderer> renderer_;
  std::mutex render_mutex_;                      // one frame at a time
  std::deque<RenderedView> kept_;                // under render_mutex_, newest first
  LiveDevelop live_develop_;                     // under render_mutex_
  std::atomic<int> frames_rendering_{0};         // waiting for or holding render_mutex_
  std::atomic<std::int64_t> last_frame_end_{0};  // steady clock ticks
};

}  // namespace rigc::studio
