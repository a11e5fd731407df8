#include "studio/live_view.h"

#include <algorithm>
#include <stdexcept>

#include "backends/registry.h"
#include "io/elapsed.h"
#include "scene/motion_blur.h"

namespace rigc::studio {
namespace {

using Clock = std::chrono::steady_clock;

std::unique_ptr<run::LiveRenderer> live_renderer_of(const std::string& name) {
  const backends::BackendEntry* entry = backends::find_backend(name);
  std::unique_ptr<run::LiveRenderer> renderer = entry ? entry->make()->live_renderer() : nullptr;
  if (!renderer) throw std::logic_error("the backend '" + name + "' has no live renderer");
  return renderer;
}

}  // namespace

LiveView::LiveView(const std::string& backend) : renderer_(live_renderer_of(backend)) {}

LiveView::~LiveView() = default;

bool LiveView::busy(std::chrono::milliseconds quiet) const {
  const Clock::duration since_frame =
      Clock::now().time_since_epoch() - Clock::duration(last_frame_end_.load());
  return frames_rendering_ > 0 || since_frame < quiet;
}

bool LiveView::RenderedView::same_view(const RenderedView& o) const {
  return o.studio == studio && o.world_from_camera == world_from_camera &&
         o.turntable_angle_rad == turntable_angle_rad &&
         o.turntable_velocity_rad_s == turntable_velocity_rad_s && o.shutter_s == shutter_s &&
         o.subframes == subframes && o.draft == draft && o.canvas.width == canvas.width &&
         o.canvas.height == canvas.height && o.canvas.fx == canvas.fx && o.canvas.fy == canvas.fy &&
         o.canvas.cx == canvas.cx && o.canvas.cy == canvas.cy;
}

// The renderer's linear frame of `shot`, or the one kept from an earlier frame that differs only
// in what the DSLR model applies (`reused`). The studio stays the same object as long as the
// object, the materials, the studio and its lights do. Null with `error` on failure.
std::shared_ptr<const run::RenderedShot> LiveView::render_linear(
    const ir::Scene& scene, const std::shared_ptr<const scene::StudioScene>& studio,
    const ir::Shot& shot, run::FrameWish wish, bool* reused, std::string* error) {
  const double scale = wish.scale;
  RenderedView view;
  view.draft = wish.draft;
  view.studio = studio;
  view.world_from_camera = shot.world_from_camera;
  view.turntable_angle_rad = shot.turntable_angle_rad;
  view.turntable_velocity_rad_s = shot.turntable_velocity_rad_s;
  view.canvas = dslr::render_geometry_for(scene.camera, scale);
  view.subframes = scene::motion_blur_subframes(scene, *studio, shot, scale);
  view.shutter_s = view.subframes > 1 ? scene.camera.shutter_s : 0;
  const auto hit = std::find_if(kept_.begin(), kept_.end(),
                                [&](const RenderedView& k) { return k.same_view(view); });
  *reused = hit != kept_.end();
  if (*reused) return hit->rendered;
  auto fresh = std::make_shared<run::RenderedShot>();
  if (!renderer_->render(scene, studio, shot, wish, fresh.get(), error)) {
    return nullptr;
  }
  view.rendered = std::move(fresh);
  kept_.push_front(std::move(view));
  // The live view's two sizes (moving and at rest) of the current view.
  if (kept_.size() > 2) kept_.pop_back();
  return kept_.front().rendered;
}

std::optional<Frame> LiveView::frame(const ir::Scene& scene,
                                     const std::shared_ptr<const scene::StudioScene>& studio,
                                     const ir::Shot& shot, run::FrameWish wish,
                                     std::string* error) {
  ++frames_rendering_;
  struct Done {
    std::atomic<int>& count;
    std::atomic<std::int64_t>& ended;
    ~Done() {
      ended = Clock::now().time_since_epoch().count();
      --count;
    }
  } done{frames_rendering_, last_frame_end_};
  std::lock_guard render_lock(render_mutex_);
  const auto start = Clock::now();
  run::RenderSettings settings;
  settings.scale = wish.scale;
  if (!settings.check(error)) return std::nullopt;
  Frame frame;
  std::shared_ptr<const run::RenderedShot> rendered =
      render_linear(scene, studio, shot, wish, &frame.reused_render, error);
  if (!rendered) return std::nullopt;
  error->clear();
  DevelopReport report;
  if (!frame.reused_render) report.stage_ms = rendered->stage_ms;
  dslr::DevelopResult developed =
      live_develop_.develop(scene.camera, std::move(rendered), shot, settings, &report, error);
  if (developed.encoded_bytes.empty()) {
    if (error->empty()) *error = "the DSLR model produced no image";
    return std::nullopt;
  }
  frame.width = developed.width;
  frame.height = developed.height;
  frame.render_ms = io::ms_since(start);
  frame.stage_ms = std::move(report.stage_ms);
  const auto encode_start = Clock::now();
  frame.jpeg =
      encode_jpeg(dslr::view_of(developed.encoded_bytes, frame.width, frame.height), 90, error);
  if (frame.jpeg.empty()) return std::nullopt;
  frame.histogram = histogram_of(developed.encoded_bytes);
  frame.encode_ms = io::ms_since(encode_start);
  return frame;
}

}  // namespace rigc::studio
