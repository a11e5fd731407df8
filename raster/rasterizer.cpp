#include "raster/rasterizer.h"

#include <atomic>
#include <cstdint>
#include <limits>
#include <memory>
#include <optional>

#include "dslr/buffer_pool.h"
#include "raster/frame_shader.h"
#include "raster/lighting.h"
#include "raster/screen_setup.h"
#include "raster/shadow_map.h"
#include "raster/shadow_map_cache.h"
#include "raster/tile_raster.h"

namespace rigc::raster {
namespace {

// A frame of the canvas's size, its buffers taken from the pool (the shading writes every pixel).
dslr::LinearFrame blank_frame(const dslr::Intrinsics& canvas) {
  dslr::LinearFrame frame;
  frame.set_intrinsics(canvas);
  const size_t pixel_count = static_cast<size_t>(canvas.width) * canvas.height;
  frame.rgb = dslr::take_floats(pixel_count * 3);
  frame.depth_m = dslr::take_floats(pixel_count);
  frame.mask = dslr::take_bytes(pixel_count);
  // Shading sums non-negative light with finite weights (GGX's roughness is floored).
  frame.rgb_clean = true;
  // Each finished tile's ranges for the depth of field, taken while its pixels are in cache.
  static_assert(kTileSize % dslr::TileRanges::kTile == 0);
  frame.tile_ranges.resize_for(canvas.width, canvas.height);
  return frame;
}

}  // namespace

dslr::LinearFrame render_frame(const ir::Scene& scene, const scene::StudioScene& studio,
                               const FrameRequest& request, RasterTimings* timings,
                               ShadowMapCache* shadow_cache) {
  // Tells this frame's per-thread caches from those any earlier frame left behind.
  static std::atomic<std::uint64_t> frames_started{0};
  const std::uint64_t frame_serial = ++frames_started;
  dslr::LinearFrame frame = blank_frame(request.canvas);
  const FrameContext context(scene, studio, request);

  const auto shadow_start = Clock::now();
  std::shared_ptr<const FrameShadowMaps> kept_maps;
  std::optional<FrameShadowMaps> own_maps;
  if (shadow_cache) {
    kept_maps =
        shadow_cache->maps(scene, studio, request.turntable_angle_rad, request.shadow_map_size);
  } else {
    own_maps.emplace(scene, studio, context.object_rot, context.object_t, request.shadow_map_size);
  }
  const FrameShadowMaps& shadow_maps = shadow_cache ? *kept_maps : *own_maps;
  if (timings) timings->shadow_ms += ms_since(shadow_start);

  const auto setup_start = Clock::now();
  const ScreenSetup setup = context.setup(request.canvas);
  if (timings) timings->setup_ms += ms_since(setup_start);

  const auto raster_start = Clock::now();
  const FrameShader shader(scene, studio, request, context, setup, shadow_maps, frame);
  const std::int64_t quads_with_block_albedos = shader.shade_tiles(frame_serial);
  if (timings) {
    timings->raster_ms += ms_since(raster_start);
    timings->quads_with_block_albedos += quads_with_block_albedos;
  }
  return frame;
}

Eigen::Vector3f diffuse_illuminance(const ir::Light& light, const Eigen::Vector3f& point,
                                    const Eigen::Vector3f& normal, const Eigen::Vector3f& to_eye,
                                    float roughness) {
  LightSample sample;
  if (!sample_light(FrameLight(light, light.color.cast<float>()), point, &sample)) {
    return Vector3f::Zero();
  }
  const float n_dot_l = normal.dot(sample.to_light);
  if (n_dot_l <= 0) return Vector3f::Zero();
  const float n_dot_v = std::max(normal.dot(to_eye), 1e-3f);
  return sample.illuminance *
         (n_dot_l * burley_diffuse(n_dot_l, n_dot_v, sample.to_light.dot(to_eye), roughness));
}

VisibilityBuffer render_visibility(const ir::Scene& scene, const scene::StudioScene& studio,
                                   const FrameRequest& request) {
  const FrameContext context(scene, studio, request);
  const ScreenSetup setup = context.setup(request.canvas);
  VisibilityBuffer buffer;
  buffer.width = request.canvas.width;
  buffer.height = request.canvas.height;
  const size_t pixel_count = static_cast<size_t>(buffer.width) * buffer.height;
  buffer.object_triangle.assign(pixel_count, -1);
  buffer.depth_m.assign(pixel_count, std::numeric_limits<float>::infinity());
  rasterize_pixels<1>(setup, request.canvas,
                      [&](int px, int py, const float* inv_z, const std::int32_t* tri) {
                        if (tri[0] < 0) return;
                        const size_t pixel = static_cast<size_t>(py) * buffer.width + px;
                        buffer.depth_m[pixel] = 1 / inv_z[0];
                        const int source = setup.tris[tri[0]].source;
                        if (source < context.object_tris) buffer.object_triangle[pixel] = source;
                      });
  return buffer;
}

std::vector<float> render_face_colors(const ir::Scene& scene, const scene::StudioScene& studio,
                                      const FrameRequest& request,
                                      const std::vector<Eigen::Vector3f>& face_colors) {
  const FrameContext context(scene, studio, request);
  const ScreenSetup setup = context.setup(request.canvas);
  std::vector<float> rgb(static_cast<size_t>(request.canvas.width) * request.canvas.height * 3,
                         0.08f);
  // Face normals lit by a headlight, so the shape reads in the picture. The view direction is
  // the pixel's own ray: one per face (its centroid's) striped planes made of thin triangles.
  const dslr::Intrinsics& canvas = request.canvas;
  const Matrix3f world_from_camera_rot = context.cam_rot.transpose();
  rasterize_pixels<kSamples>(
      setup, canvas, [&](int px, int py, const float*, const std::int32_t* tri) {
        const Vector3f ray(static_cast<float>((px + 0.5 - canvas.cx) / canvas.fx),
                           static_cast<float>((py + 0.5 - canvas.cy) / canvas.fy), 1.0f);
        const Vector3f view = (world_from_camera_rot * ray).normalized();
        Vector3f color = Vector3f::Zero();
        for (int k = 0; k < kSamples; ++k) {
          if (tri[k] < 0) {
            color += Vector3f::Constant(0.08f);
            continue;
          }
          const int t = setup.tris[tri[k]].source;
          const Vector3f a = context.world_vertex(t, 0), b = context.world_vertex(t, 1),
                         c = context.world_vertex(t, 2);
          const Vector3f normal = (b - a).cross(c - a).normalized();
          const float light = 0.35f + 0.65f * std::abs(normal.dot(view));
          const Vector3f base = t < context.object_tris && t < static_cast<int>(face_colors.size())
                                    ? face_colors[t]
                                    : Vector3f(0.35f, 0.35f, 0.35f);
          color += base * light;
        }
        color /= kSamples;
        const size_t pixel = (static_cast<size_t>(py) * canvas.width + px) * 3;
        rgb[pixel] = color.x();
        rgb[pixel + 1] = color.y();
        rgb[pixel + 2] = color.z();
      });
  return rgb;
}

}  // namespace rigc::raster
