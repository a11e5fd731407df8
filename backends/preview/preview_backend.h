// The fast preview backend: every shot through RigC's rasterizer (raster/), motion blur as
// sub-frames averaged over the open shutter.
#pragma once

#include <cstdint>

#include "dslr/frame.h"
#include "ir/ir.h"
#include "run/backend.h"
#include "run/run_loop.h"
#include "scene/studio_scene.h"

namespace rigc::raster {
class ShadowMapCache;
}

namespace rigc::preview {

// How the preview renders beyond the scene. The defaults are `rigc render`'s; the rest serve the
// studio's drafts and the benchmark that weighs each difference from the references
// (bench/ablation_table.cpp).
struct RenderOptions {
  // Textures and patterns point-sampled (raster::FrameRequest::draft_surface).
  bool draft_surface = false;
  // Each pixel rendered as supersample x supersample pixels averaged (shading, geometry and
  // surface sampled that much finer), as a reference's many samples a pixel are. A run's
  // RenderSettings::samples, when not 0, set it (PreviewBackend::takes_samples).
  int supersample = 1;
  // False leaves the lights' specular lobe out (raster::FrameRequest::specular).
  bool specular = true;
  // Lights summed for every pixel instead of once per 2 x 2 quad
  // (raster::FrameRequest::per_pixel_lighting).
  bool per_pixel_lighting = false;

  // The options that differ from the defaults, as text for the shot key ("" when none).
  std::string key() const;
};

class PreviewBackend : public run::Backend {
 public:
  std::string name() const override { return "preview"; }
  RenderOptions options;
  std::string options_key() const override { return options.key(); }
  // RenderSettings::samples: n x n a pixel (RenderOptions::supersample), 0 for one. The grid
  // must be square, and the finer canvas no larger than the sensor (memory stays within the
  // full-resolution render's).
  bool takes_samples() const override { return true; }
  int default_samples() const override { return 1; }
  bool check_settings(const run::RenderSettings& settings, std::string* error) const override;
  // Raised with every change to the preview's pixels, so that earlier runs render again (the
  // history is in git log).
  int output_version() const override { return 6; }
  bool render(const ir::Scene& scene, const scene::StudioScene& studio, const ir::Shot& shot,
              const run::RenderSettings& settings, const run::ShotFiles& files,
              run::RenderedShot* out, std::string* error) override;
  // Keeps the shadow maps while the studio stays; a draft point-samples the surface.
  std::unique_ptr<run::LiveRenderer> live_renderer() const override;
};

// One shot in linear light, with the rasterizer's stages in stage_ms. A `shadow_cache` keeps the
// shadow maps of a frame without motion blur for the next (raster/shadow_map_cache.h).
run::RenderedShot render_linear(const ir::Scene& scene, const scene::StudioScene& studio,
                                const ir::Shot& shot, double scale,
                                raster::ShadowMapCache* shadow_cache = nullptr,
                                const RenderOptions& options = {});

// The shot's unlit albedo (base colour x texture x pattern) as radiance, with its mask: no
// lights, shadows or motion blur.
dslr::LinearFrame render_albedo(const ir::Scene& scene, const scene::StudioScene& studio,
                                const ir::Shot& shot, double scale);

// Renders and develops one shot (no files), for tests and benchmarks. Without `keep_linear` the
// result's linear image is left empty (what a run that writes files does).
// (Eight parameters, the last three optional: tests and benchmarks name what they read.)
dslr::DevelopResult render_shot(const ir::Scene& scene, const scene::StudioScene& studio,
                                const ir::Shot& shot, double scale, std::uint64_t seed,
                                run::ShotTiming* timing = nullptr,
                                dslr::LinearFrame* linear_out = nullptr, bool keep_linear = true);

}  // namespace rigc::preview
