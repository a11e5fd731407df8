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

class PreviewBackend : public run::Backend {
 public:
  std::string name() const override { return "preview"; }
  // Point-samples textures and patterns as the studio's drafts do: for the benchmark that weighs
  // what the surface filter does to a reconstruction (bench/ablation_table.cpp).
  bool draft_surface = false;
  // Renders each pixel as supersample x supersample pixels averaged (shading, geometry and surface
  // sampled that much finer): for the same benchmark, to weigh the preview's one shading point a
  // pixel against a reference's many samples.
  int supersample = 1;
  // False leaves the lights' specular lobe out (raster::FrameRequest::specular).
  bool specular = true;
  // Lights summed for every pixel instead of once per 2 x 2 quad
  // (raster::FrameRequest::per_pixel_lighting).
  bool per_pixel_lighting = false;
  std::string options_key() const override;
  bool render(const ir::Scene& scene, const scene::StudioScene& studio, const ir::Shot& shot,
              const run::RenderSettings& settings, const run::ShotFiles& files,
              run::RenderedShot* out, std::string* error) override;
};

// One shot in linear light, with the rasterizer's stages in stage_ms. A `shadow_cache` keeps the
// shadow maps of a frame without motion blur for the next (raster/shadow_map_cache.h); a
// `draft_surface` point-samples textures and patterns (raster::FrameRequest::draft_surface).
run::RenderedShot render_linear(const ir::Scene& scene, const scene::StudioScene& studio,
                                const ir::Shot& shot, double scale,
                                raster::ShadowMapCache* shadow_cache = nullptr,
                                bool draft_surface = false, int supersample = 1,
                                bool specular = true, bool per_pixel_lighting = false);

// The shot's unlit albedo (base colour x texture x pattern) as radiance, with its mask: no
// lights, shadows or motion blur.
dslr::LinearFrame render_albedo(const ir::Scene& scene, const scene::StudioScene& studio,
                                const ir::Shot& shot, double scale);

// Renders and develops one shot (no files), for tests and benchmarks. Without `keep_linear` the
// result's linear image is left empty (what a run that writes files does).
dslr::DevelopResult render_shot(const ir::Scene& scene, const scene::StudioScene& studio,
                                const ir::Shot& shot, double scale, std::uint64_t seed,
                                run::ShotTiming* timing = nullptr,
                                dslr::LinearFrame* linear_out = nullptr, bool keep_linear = true);

}  // namespace rigc::preview
