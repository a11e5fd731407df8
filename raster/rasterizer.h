// The preview's renderer: a multithreaded tile rasterizer with 4 samples per pixel (rotated grid),
// perspective-correct attributes, shading in scene-linear luminance units (cd/m²) from the lights'
// physical units, and shadow maps (soft for area lights).
#pragma once

#include <cstdint>
#include <vector>

#include "dslr/frame.h"
#include "ir/ir.h"
#include "scene/studio_scene.h"

namespace rigc::raster {

struct FrameRequest {
  ir::Mat4 world_from_camera = ir::Mat4::Identity();
  double turntable_angle_rad = 0;
  dslr::Intrinsics canvas;  // undistorted pinhole grid to render
  int shadow_map_size = 2048;
  // Lights are summed once per 2 x 2 quad inside a surface (albedo stays per pixel); true sums
  // them for every pixel (tests compare the two).
  bool per_pixel_lighting = false;
  // A 4 x 4 block of the object that fails its light check hands its albedos to the quads that
  // then shade its pixels (where the pattern is fully resolved, they are the quads' own); false
  // makes the quads evaluate every albedo (tests compare the two).
  bool reuse_block_albedos = true;
  // Every surface sends its albedo (base colour x texture x pattern) as its radiance, unlit:
  // the albedo agreement test compares this with the ray tracers' emission-only renders.
  bool albedo_only = false;
  // Textures and patterns point-sampled at each pixel's centre (trilinear mip levels; a pattern
  // still fades to its mean where too fine) instead of box-filtered over the pixel: the
  // studio's frames while the camera moves.
  bool draft_surface = false;
  // False leaves the lights' specular lobe out (the diffuse part is unchanged): for the benchmark
  // that weighs what the specular response does to a reconstruction (bench/ablation_table.cpp).
  bool specular = true;
};

struct RasterTimings {
  double shadow_ms = 0;
  double setup_ms = 0;                        // transform, clip, project, bin
  double raster_ms = 0;                       // visibility and shading
  std::int64_t quads_with_block_albedos = 0;  // quads that took a failed block's albedos
};

class ShadowMapCache;

// Renders radiance (cd/m² per channel), camera-space depth and the object mask. With a
// `shadow_cache` (see shadow_map_cache.h), shadow maps kept from earlier frames serve.
dslr::LinearFrame render_frame(const ir::Scene& scene, const scene::StudioScene& studio,
                               const FrameRequest& request, RasterTimings* timings = nullptr,
                               ShadowMapCache* shadow_cache = nullptr);

// A light's diffuse reflection at a surface point, as the illuminance (lux, per linear RGB
// channel) a Lambertian surface would need to give it: the illuminance on the surface with
// normal n, shaped by Burley's lobe for a view towards `to_eye` and the surface's roughness;
// shadows ignored. The same radiometry the renderer shades with.
Eigen::Vector3f diffuse_illuminance(const ir::Light& light, const Eigen::Vector3f& point,
                                    const Eigen::Vector3f& normal, const Eigen::Vector3f& to_eye,
                                    float roughness);

// Visibility only, one sample per pixel centre: the nearest object triangle (-1 where the studio
// or nothing is seen) and the camera-space depth of whatever is nearest. For coverage analysis.
struct VisibilityBuffer {
  int width = 0;
  int height = 0;
  std::vector<std::int32_t> object_triangle;
  std::vector<float> depth_m;
};
VisibilityBuffer render_visibility(const ir::Scene& scene, const scene::StudioScene& studio,
                                   const FrameRequest& request);

// A picture of the object with one flat colour per triangle (linear RGB), lit by a headlight;
// the studio in grey. 4 samples per pixel. Returns 3 floats per pixel.
std::vector<float> render_face_colors(const ir::Scene& scene, const scene::StudioScene& studio,
                                      const FrameRequest& request,
                                      const std::vector<Eigen::Vector3f>& face_colors);

}  // namespace rigc::raster
