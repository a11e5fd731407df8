// The preview's renderer: a multithreaded tile rasterizer with 4 samples per pixel (rotated grid),
// perspective-correct attributes, shading in scene-linear luminance units (cd/m²) from the lights'
// physical units, and shadow maps (soft for area lights).
#pragma once

#include <vector>

#include "backends/preview/studio_scene.h"
#include "compiler/ir.h"
#include "dslr/frame.h"

namespace rigc::preview {

struct FrameRequest {
  ir::Mat4 world_from_camera = ir::Mat4::Identity();
  double turntable_angle_rad = 0;
  dslr::Intrinsics canvas;   // undistorted pinhole grid to render
  int shadow_map_size = 2048;
};

struct RasterTimings {
  double shadow_ms = 0;
  double setup_ms = 0;   // transform, clip, project, bin
  double raster_ms = 0;  // visibility and shading
};

// Renders radiance (cd/m² per channel), camera-space depth and the object mask.
dslr::LinearFrame render_frame(const ir::Scene& scene, const StudioScene& studio,
                               const FrameRequest& request, RasterTimings* timings = nullptr);

}  // namespace rigc::preview
