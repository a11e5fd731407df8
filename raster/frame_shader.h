// Internal to the rasterizer: what a frame's surfaces look like. FrameShader works out, for a
// point of a screen triangle, its surface (position, normals), its albedo (base
// colour, texture, pattern) and the light it sends to the camera, and writes shaded pixels;
// shade_tiles drives the tile raster and shades every tile (frame_shader.cpp), the plain studio
// planes through StudioPlanes (studio_planes.h).
#pragma once

#include <array>
#include <cstdint>
#include <vector>

#include "dslr/frame.h"
#include "raster/lighting.h"
#include "raster/raster_common.h"
#include "raster/rasterizer.h"
#include "raster/screen_setup.h"
#include "raster/shadow_map.h"
#include "scene/studio_scene.h"

namespace rigc::raster {

// Lighting is summed at the corners of blocks of kBlock x kBlock pixels and interpolated where
// it varies smoothly: kCorners x kCorners corners per tile.
inline constexpr int kBlock = 4;
inline constexpr int kCorners = kTileSize / kBlock + 1;

// The mesh triangle a screen triangle came from: object triangles first, then the studio's.
struct SourceTriangle {
  const scene::Geometry& g;
  int local;  // index in g
  bool is_object;
  const std::array<std::uint32_t, 3>& corners() const { return g.triangles[local]; }
  int material() const { return g.triangle_material[local]; }
  // A per-vertex attribute at barycentrics b.
  template <typename T>
  T at(const std::vector<T>& values, const Vector3f& b) const {
    const auto& c = corners();
    return b.x() * values[c[0]] + b.y() * values[c[1]] + b.z() * values[c[2]];
  }
};

// A point on one triangle as the camera sees it: everything shading needs besides the lights.
struct SurfacePoint {
  Vector3f p;          // world
  Vector3f n;          // unit shading normal, turned towards the viewer
  Vector3f geometric;  // unit face normal, turned towards the viewer (shadow bias)
  Vector3f v;          // unit, towards the eye
  int material;
};

// Base colour x texture at a pixel, and where the pixel sees the object (in its own frame) to
// read the surface pattern, when it has one.
struct AlbedoSample {
  Vector3f color;
  scene::PixelOnSurface pattern_at;
  bool patterned = false;
};

// The BRDF is linear in the albedo, so the light a surface point sends to the camera is
// albedo ⊙ scale + offset: the lights are summed once and the albedo applied per pixel.
struct Lighting {
  Vector3f scale, offset;
};

// A pixel's samples grouped into surfaces (same object membership, depths within 1 %): each is
// shaded once, with the triangle holding most of its samples; only silhouettes blend surfaces.
struct PixelSurfaces {
  int count = 0;
  std::array<std::int32_t, kSamples> triangle;  // screen triangle shading each surface
  std::array<int, kSamples> samples;            // samples it covers
  int object_samples = 0;
  float nearest = 0;  // largest 1/z
};

class FrameShader {
 public:
  FrameShader(const ir::Scene& scene, const scene::StudioScene& studio, const FrameRequest& request,
              const FrameContext& context, const ScreenSetup& setup,
              const FrameShadowMaps& shadow_maps, dslr::LinearFrame& frame);

  // Rasterizes and shades every tile into the frame; `frame_serial` tells this frame from
  // earlier ones (see StudioPlanes). Returns how many quads took a failed block's albedos.
  std::int64_t shade_tiles(std::uint64_t frame_serial) const;

  const ScreenTriangle& screen_triangle(std::int32_t id) const { return screen_tris_[id]; }
  SourceTriangle source_of(const ScreenTriangle& s) const {
    const bool is_object = s.source < object_tris_;
    return {is_object ? object_ : room_, is_object ? s.source : s.source - object_tris_, is_object};
  }
  bool on_object(const ScreenTriangle& s) const { return s.source < object_tris_; }
  const scene::ShadedMaterial& material(int index) const { return studio_.materials[index]; }
  const FrameRequest& request() const { return request_; }
  // Lighting summed per block of pixels rather than per quad (FrameRequest::per_pixel_lighting).
  bool use_blocks() const { return use_blocks_; }
  // Pixels per radian (the canvas's focal length).
  float focal() const { return fx_; }

  // Barycentrics in the source triangle at (px, py), clamped to it.
  Vector3f source_bary_at(const ScreenTriangle& s, float px, float py) const {
    const Vector3f b = setup_.source_bary(s, screen_bary(s, px, py)).cwiseMax(0.0f);
    return b * (1 / b.sum());
  }
  // The point of screen triangle s under (px, py); `on_plane`: barycentrics unclamped, so points
  // past the triangle's edges stay on its plane.
  SurfacePoint surface_at(const ScreenTriangle& s, float px, float py, bool on_plane = false) const;
  // Whether the shading normal at (px, py) agrees with that of `centre` (kQuadNormalCos).
  bool normal_agrees(const ScreenTriangle& s, float px, float py, const SurfacePoint& centre) const;
  AlbedoSample albedo_sample_at(const ScreenTriangle& s, float px, float py) const;
  // The box filters' samples per pixel side: one in a draft (see FrameRequest::draft_surface).
  int pattern_filter_side() const {
    return request_.draft_surface ? 1 : scene::kMaxPatternFilterSide;
  }
  int texture_filter_side() const { return request_.draft_surface ? 1 : 4; }
  // Base colour x texture x surface pattern at (px, py) on the screen triangle.
  Vector3f albedo_at(const ScreenTriangle& s, float px, float py) const;
  // albedo_at for up to kMaxBatch pixels of one material at once (the pattern's samples are
  // evaluated eight at a time): pixel i at (px[i], py[i]) on screen triangle tris[i].
  static constexpr int kMaxBatch = 16;
  void albedo_batch(const int* tris, const int* px, const int* py, int count, Vector3f* out) const;
  // The lights (shadows included) and the ambient term at a surface point.
  Lighting lighting_at(const SurfacePoint& sp) const;
  // Four pixels of one surface and material, each shaded as shade() does (its own normal and
  // light), with their albedos batched: pixel i at (px[i], py[i]) on screen triangle tris[i].
  // known(px, py, albedo) may supply the albedos (true) instead.
  template <typename KnownAlbedos>
  void shade_four(const int* tris, const int* px, const int* py, const KnownAlbedos& known,
                  Vector3f* out) const;
  // Studio triangles without a texture: one colour over a plane, lit smoothly.
  bool plain_studio(const ScreenTriangle& t) const {
    return t.source >= object_tris_ && studio_.materials[source_of(t).material()].texture < 0;
  }
  // Two studio triangles of one material on one plane (their face normals agree).
  bool same_studio_plane(const ScreenTriangle& a, const ScreenTriangle& b) const;
  // A plain studio plane's radiance at (px, py), which may lie outside the triangle.
  Vector3f shade_on_plane(const ScreenTriangle& s, float px, float py) const;
  // Radiance of screen triangle s at (px, py).
  Vector3f shade(const ScreenTriangle& s, float px, float py) const;

  // A pixel whose samples all hold screen triangle `id` (object_samples: kSamples on the
  // object, 0 on the studio), as group_samples finds it.
  static PixelSurfaces single_surface(const float* inv_z, std::int32_t id, int object_samples);
  PixelSurfaces group_samples(const float* inv_z, const std::int32_t* tri) const;
  // The pixel's colour, depth (of its nearest sample) and mask.
  void write_pixel(int px, int py, const PixelSurfaces& surfaces, const Vector3f& color) const;
  // Each surface of the pixel shaded on its own and blended by its samples.
  void shade_pixel(int px, int py, const PixelSurfaces& surfaces) const;
  // The finished tile's ranges for the depth of field, taken while its pixels are in cache.
  void record_ranges(int x0, int y0, int x1, int y1) const;

  dslr::LinearFrame& frame() const { return frame_; }

 private:
  const scene::StudioScene& studio_;
  const FrameRequest& request_;
  const ScreenSetup& setup_;
  const std::vector<ScreenTriangle>& screen_tris_;
  const FrameShadowMaps& shadow_maps_;
  dslr::LinearFrame& frame_;
  const scene::Geometry& object_;
  const scene::Geometry& room_;
  const Matrix3f& object_rot_;
  const Vector3f& object_t_;
  const Matrix3f& cam_rot_;
  const Vector3f& cam_t_;
  const Vector3f& eye_;
  const int object_tris_;
  const float fx_;
  const bool use_blocks_;
  std::vector<FrameLight> lights_;
  const float ambient_lx_;
};

}  // namespace rigc::raster
