#include "backends/preview/preview_backend.h"

#include <fmt/format.h>
#include <fmt/ranges.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <memory>
#include <string>
#include <vector>

#include "dslr/lens.h"
#include "io/elapsed.h"
#include "raster/rasterizer.h"
#include "raster/shadow_map_cache.h"
#include "scene/motion_blur.h"

namespace rigc::preview {

namespace {

using Clock = std::chrono::steady_clock;

// Sub-frames spread evenly over the open shutter, centred on the shot's angle, averaged. Depth
// and mask come from the middle one.
dslr::LinearFrame render_motion_blurred(const ir::Scene& scene, const scene::StudioScene& studio,
                                        const ir::Shot& shot, int subframes,
                                        raster::FrameRequest request,
                                        raster::RasterTimings* timings) {
  const double sweep = shot.turntable_velocity_rad_s * scene.camera.shutter_s;
  dslr::LinearFrame frame;
  std::vector<double> sum;
  for (int k = 0; k < subframes; ++k) {
    request.turntable_angle_rad = shot.turntable_angle_rad + sweep * ((k + 0.5) / subframes - 0.5);
    dslr::LinearFrame sub = raster::render_frame(scene, studio, request, timings);
    if (sum.empty()) sum.assign(sub.rgb.size(), 0.0);
    for (size_t i = 0; i < sub.rgb.size(); ++i) sum[i] += sub.rgb[i];
    if (k == subframes / 2) frame = std::move(sub);
  }
  for (size_t i = 0; i < sum.size(); ++i) frame.rgb[i] = static_cast<float>(sum[i] / subframes);
  frame.tile_ranges = {};  // they described the middle sub-frame alone
  return frame;
}

// The side of the square sample grid of `samples` a pixel, rounded down.
int grid_side(int samples) {
  int side = static_cast<int>(std::sqrt(static_cast<double>(samples)));
  while (static_cast<long long>(side + 1) * (side + 1) <= samples) ++side;
  return std::max(side, 1);
}

// The frame `factor` times smaller on each side: radiance averaged, the nearest depth kept (the
// depth of field blurs a pixel by its foreground), the mask set where most samples were object.
dslr::LinearFrame box_downsample(const dslr::LinearFrame& fine, int factor,
                                 const dslr::Intrinsics& canvas) {
  dslr::LinearFrame out;
  out.set_intrinsics(canvas);
  out.rgb_clean = fine.rgb_clean;
  const std::size_t pixels = static_cast<std::size_t>(canvas.width) * canvas.height;
  out.rgb.assign(3 * pixels, 0.0f);
  out.depth_m.assign(pixels, std::numeric_limits<float>::infinity());
  if (!fine.mask.empty()) out.mask.assign(pixels, 0);
  const float weight = 1.0f / static_cast<float>(factor * factor);
  for (int y = 0; y < canvas.height; ++y) {
    for (int x = 0; x < canvas.width; ++x) {
      const std::size_t o = static_cast<std::size_t>(y) * canvas.width + x;
      int object_samples = 0;
      for (int sy = 0; sy < factor; ++sy) {
        for (int sx = 0; sx < factor; ++sx) {
          const std::size_t i = static_cast<std::size_t>(y * factor + sy) * fine.width +
                                static_cast<std::size_t>(x * factor + sx);
          for (int c = 0; c < 3; ++c) out.rgb[3 * o + c] += weight * fine.rgb[3 * i + c];
          out.depth_m[o] = std::min(out.depth_m[o], fine.depth_m[i]);
          if (!fine.mask.empty() && fine.mask[i] != 0) ++object_samples;
        }
      }
      if (!out.mask.empty() && 2 * object_samples >= factor * factor) out.mask[o] = 255;
    }
  }
  return out;
}

}  // namespace

std::string RenderOptions::key() const {
  std::vector<std::string> changed;
  if (draft_surface) changed.push_back("draft_surface");
  if (supersample != 1) changed.push_back(fmt::format("supersample={}", supersample));
  if (!specular) changed.push_back("no_specular");
  if (per_pixel_lighting) changed.push_back("per_pixel_lighting");
  return fmt::format("{}", fmt::join(changed, ";"));
}

run::RenderedShot render_linear(const ir::Scene& scene, const scene::StudioScene& studio,
                                const ir::Shot& shot, double scale,
                                raster::ShadowMapCache* shadow_cache,
                                const RenderOptions& options) {
  const dslr::RenderGeometry geometry = dslr::render_geometry_for(scene.camera, scale);
  const int supersample = options.supersample;
  raster::FrameRequest request;
  request.draft_surface = options.draft_surface;
  request.specular = options.specular;
  request.per_pixel_lighting = options.per_pixel_lighting;
  request.world_from_camera = shot.world_from_camera;
  request.canvas = geometry;
  request.canvas.width *= supersample;
  request.canvas.height *= supersample;
  for (double* v :
       {&request.canvas.fx, &request.canvas.fy, &request.canvas.cx, &request.canvas.cy}) {
    *v *= supersample;
  }
  request.shadow_map_size = std::clamp(request.canvas.width / 2, 512, 2048);
  run::RenderedShot out;
  out.subframes = scene::motion_blur_subframes(scene, studio, shot, scale);
  raster::RasterTimings timings;
  if (out.subframes == 1) {
    request.turntable_angle_rad = shot.turntable_angle_rad;
    out.frame = raster::render_frame(scene, studio, request, &timings, shadow_cache);
  } else {
    out.frame = render_motion_blurred(scene, studio, shot, out.subframes, request, &timings);
  }
  if (supersample > 1) out.frame = box_downsample(out.frame, supersample, geometry);
  out.stage_ms = {{"shadows", timings.shadow_ms},
                  {"setup", timings.setup_ms},
                  {"raster_and_shading", timings.raster_ms}};
  return out;
}

dslr::LinearFrame render_albedo(const ir::Scene& scene, const scene::StudioScene& studio,
                                const ir::Shot& shot, double scale) {
  raster::FrameRequest request;
  request.world_from_camera = shot.world_from_camera;
  request.canvas = dslr::render_geometry_for(scene.camera, scale);
  request.turntable_angle_rad = shot.turntable_angle_rad;
  request.albedo_only = true;
  return raster::render_frame(scene, studio, request);
}

bool PreviewBackend::check_settings(const run::RenderSettings& settings, std::string* error) const {
  if (settings.samples == 0) return true;
  const int grid = grid_side(settings.samples);
  if (grid * grid != settings.samples) {
    *error = fmt::format(
        "the preview takes a square number of samples per pixel (1, 4, 9, 16, ...), not {}",
        settings.samples);
    return false;
  }
  if (grid > 1 && grid * settings.scale > 1.0) {
    const int most = std::max(1, static_cast<int>(std::floor(1.0 / settings.scale + 1e-9)));
    *error = fmt::format(
        "{} samples per pixel at scale {} would render the preview larger than the sensor; at "
        "this scale it takes at most {} ({} x {})",
        settings.samples, settings.scale, most * most, most, most);
    return false;
  }
  return true;
}

bool PreviewBackend::render(const ir::Scene& scene, const scene::StudioScene& studio,
                            const ir::Shot& shot, const run::RenderSettings& settings,
                            const run::ShotFiles& /*files*/, run::RenderedShot* out,
                            std::string* /*error*/) {
  RenderOptions shot_options = options;
  if (settings.samples > 0) shot_options.supersample = grid_side(settings.samples);
  *out = render_linear(scene, studio, shot, settings.scale, nullptr, shot_options);
  return true;
}

namespace {

class PreviewLiveRenderer : public run::LiveRenderer {
 public:
  bool render(const ir::Scene& scene, const std::shared_ptr<const scene::StudioScene>& studio,
              const ir::Shot& shot, run::FrameWish wish, run::RenderedShot* out,
              std::string* /*error*/) override {
    if (shadow_studio_ != studio || !shadow_cache_) {
      shadow_cache_ = std::make_unique<raster::ShadowMapCache>();
      shadow_studio_ = studio;
    }
    *out = render_linear(scene, *studio, shot, wish.scale, shadow_cache_.get(),
                         {.draft_surface = wish.draft});
    return true;
  }

 private:
  // The shadow maps of shadow_studio_'s lights (whoever changes the lights makes a new studio).
  std::shared_ptr<const scene::StudioScene> shadow_studio_;
  std::unique_ptr<raster::ShadowMapCache> shadow_cache_;
};

}  // namespace

std::unique_ptr<run::LiveRenderer> PreviewBackend::live_renderer() const {
  return std::make_unique<PreviewLiveRenderer>();
}

dslr::DevelopResult render_shot(const ir::Scene& scene, const scene::StudioScene& studio,
                                const ir::Shot& shot, double scale, std::uint64_t seed,
                                run::ShotTiming* timing, dslr::LinearFrame* linear_out,
                                bool keep_linear) {
  const auto start = Clock::now();
  run::RenderedShot rendered = render_linear(scene, studio, shot, scale);
  if (linear_out) *linear_out = rendered.frame;
  run::RenderSettings settings;
  settings.scale = scale;
  settings.seed = seed;
  run::ShotTiming shot_timing;
  shot_timing.stage_ms = rendered.stage_ms;
  shot_timing.subframes = rendered.subframes;
  dslr::DevelopResult result = run::develop_shot(scene, shot, std::move(rendered), settings,
                                                 keep_linear, nullptr, &shot_timing.stage_ms);
  shot_timing.total_ms = io::ms_since(start);
  if (timing) *timing = std::move(shot_timing);
  return result;
}

}  // namespace rigc::preview
