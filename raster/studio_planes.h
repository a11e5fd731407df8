// Internal to the rasterizer: the studio's plain planes (untextured, one colour each). Over a
// 4 x 4 block within one plane the light varies smoothly (soft shadows included), so it is summed
// at the blocks' corners and interpolated, corners shared between blocks; where a pixel spans a
// small enough angle, only every second, fourth or eighth corner is shaded (see StudioPlanes).
#pragma once

#include <array>
#include <cstdint>

#include "raster/frame_shader.h"

namespace rigc::raster {

// Radiance at the corners of a tile's 4 x 4 blocks on a plain studio plane, cached per tile
// and plane. On the plane: unclamped barycentrics reach past the triangle's edges along it.
struct PlaneCorners {
  // One corner of padding: a row's last corner is read as four floats.
  std::array<Vector3f, kCorners * kCorners + 1> color;
  std::array<std::int32_t, kCorners * kCorners> plane;  // source triangle, -1: not yet
  PlaneCorners() { plane.fill(-1); }
};

class StudioPlanes {
 public:
  // `frame_serial` tells this frame's per-thread caches from those an earlier frame left.
  StudioPlanes(const FrameShader& shader, std::uint64_t frame_serial);

  // Corner (cx, cy) of the grid of the tile at (x0, y0) on `plane`, through `cache`.
  Vector3f corner(PlaneCorners& cache, const ScreenTriangle& plane, int x0, int y0, int cx,
                  int cy) const {
    const int slot = cy * kCorners + cx;
    if (cache.plane[slot] == plane.source) return cache.color[slot];
    return new_corner(cache, plane, x0, y0, cx, cy);
  }

  // A tile inside one plain studio triangle (screen triangle `id`) that nothing else in its bin
  // touches: every sample is that plane, so the tile is its blocks' interpolated corners, the
  // depth the plane's nearest sample per pixel and the mask empty, without the per-sample
  // buffers. False (nothing written) when the triangle is not a plain studio one.
  bool fill_tile(int x0, int y0, int x1, int y1, std::int32_t id) const;

 private:
  Vector3f new_corner(PlaneCorners& cache, const ScreenTriangle& plane, int x0, int y0, int cx,
                      int cy) const;
  // All the tile's corners into `cache`, `columns` x `rows` blocks.
  void tile_corners_of(PlaneCorners& cache, const ScreenTriangle& plane, std::int32_t id, int x0,
                       int y0, int x1, int columns, int rows) const;
  // The tile's pixels: colours blended from the corners, depth of the plane, mask empty.
  void write_tile(const PlaneCorners& cache, const ScreenTriangle& plane, int x0, int y0, int x1,
                  int y1) const;

  const FrameShader& shader_;
  const std::uint64_t frame_serial_;
  // Where 8 pixels subtend under 1.5 mrad (the full-resolution frames of a normal lens), the
  // studio planes are shaded every 8 pixels: their light, soft shadows included, does not bend
  // over that span, and the green screen and the turntable fill most of a frame.
  const bool coarse_corners_;
  // Where 16 pixels subtend under 2.5 mrad, the plane is first shaded every 16 pixels; a 16 px
  // cell whose four corners agree within kWideCellTolerance (relative, per channel) is
  // interpolated from them, any other is shaded every 8 pixels as above. Light falling off over
  // a plane changes far less than that across 16 px; a shadow edge or a penumbra changes more.
  const bool wide_corners_;
  // And where 32 pixels (a tile) subtend under 5 mrad, the same one level up: the plane is first
  // shaded at the tiles' corners, and a tile whose corners agree within kTileCellTolerance takes
  // its 16 px corners from them (the full-resolution frames of a normal lens, whose green screen
  // is mostly such tiles). Half the cells' tolerance: a curve's departure from the blend grows
  // with the square of the cell's size.
  const bool tile_corners_;
};

}  // namespace rigc::raster
