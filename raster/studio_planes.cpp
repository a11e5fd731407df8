#include "raster/studio_planes.h"

#include <algorithm>
#include <cstring>
#include <limits>

namespace rigc::raster {
namespace {

constexpr float kWideCellTolerance = 0.01f;
constexpr float kTileCellTolerance = 0.005f;

// Whether a cell's four corner radiances agree within `tolerance` (relative, per channel).
bool corners_agree(const Vector3f& c00, const Vector3f& c10, const Vector3f& c01,
                   const Vector3f& c11, float tolerance) {
  const Vector3f lo = c00.cwiseMin(c10).cwiseMin(c01).cwiseMin(c11);
  const Vector3f hi = c00.cwiseMax(c10).cwiseMax(c01).cwiseMax(c11);
  return ((hi - lo).array() <= tolerance * hi.array()).all();
}

}  // namespace

StudioPlanes::StudioPlanes(const FrameShader& shader, std::uint64_t frame_serial)
    : shader_(shader),
      frame_serial_(frame_serial),
      coarse_corners_(shader.use_blocks() && 2 * kBlock / shader.focal() <= 1.5e-3f),
      wide_corners_(coarse_corners_ && 4 * kBlock / shader.focal() <= 2.5e-3f),
      tile_corners_(wide_corners_ && 8 * kBlock / shader.focal() <= 5e-3f) {}

// With coarse corners only the even ones are shaded and odd ones are the mean of their even
// neighbours; with wide corners the even ones come from the 16 px cell's corners where those
// agree, and with tile corners those from the tile's.
Vector3f StudioPlanes::new_corner(PlaneCorners& cache, const ScreenTriangle& plane, int x0, int y0,
                                  int cx, int cy) const {
  auto at = [&](int ax, int ay) { return corner(cache, plane, x0, y0, ax, ay); };
  auto shaded = [&] {
    return shader_.shade_on_plane(plane, static_cast<float>(x0 + kBlock * cx),
                                  static_cast<float>(y0 + kBlock * cy));
  };
  // Interpolated within the cell whose corners are (ax, ay) and (bx, by) when those agree
  // within `tolerance` (relative, per channel); shaded otherwise.
  auto from_cell = [&](int ax, int bx, int ay, int by, int cell, float tolerance) {
    const Vector3f c00 = at(ax, ay), c10 = at(bx, ay), c01 = at(ax, by), c11 = at(bx, by);
    if (corners_agree(c00, c10, c01, c11, tolerance)) {
      const float tx = static_cast<float>(cx % cell) / static_cast<float>(cell);
      const float ty = static_cast<float>(cy % cell) / static_cast<float>(cell);
      return Vector3f((1 - ty) * ((1 - tx) * c00 + tx * c10) + ty * ((1 - tx) * c01 + tx * c11));
    }
    return shaded();
  };
  Vector3f color;
  if (tile_corners_ && cx % 4 == 0 && cy % 4 == 0 && (cx % 8 || cy % 8)) {
    // A corner on a tile's edge looks at that edge's two ends only, as below.
    const int ax = cx - cx % 8, bx = cx % 8 ? ax + 8 : ax;
    const int ay = cy - cy % 8, by = cy % 8 ? ay + 8 : ay;
    color = from_cell(ax, bx, ay, by, 8, kTileCellTolerance);
  } else if (wide_corners_ && cx % 2 == 0 && cy % 2 == 0 && (cx % 4 || cy % 4)) {
    // A corner on a 16 px cell's edge looks at that edge's two ends only (all that its
    // interpolation uses), so the tiles on both sides of a tile border decide alike.
    const int ax = cx - cx % 4, bx = cx % 4 ? ax + 4 : ax;
    const int ay = cy - cy % 4, by = cy % 4 ? ay + 4 : ay;
    color = from_cell(ax, bx, ay, by, 4, kWideCellTolerance);
  } else if (coarse_corners_ && (cx % 2 || cy % 2)) {
    const int ax = cx - cx % 2, bx = cx + cx % 2;
    const int ay = cy - cy % 2, by = cy + cy % 2;
    color = 0.25f * (at(ax, ay) + at(bx, ay) + at(ax, by) + at(bx, by));
  } else {
    color = shaded();
  }
  const int slot = cy * kCorners + cx;
  cache.plane[slot] = plane.source;
  cache.color[slot] = color;
  return color;
}

// (Eight parameters: a tile's rectangle and its plane, called per tile by the rasterizer.)
void StudioPlanes::tile_corners_of(PlaneCorners& cache, const ScreenTriangle& plane,
                                   std::int32_t id, int x0, int y0, int x1, int columns,
                                   int rows) const {
  // The tile this thread did just before, when it is the left neighbour on the same screen
  // triangle: its right column of corners is this tile's left one, the same values (a corner
  // on a tile's border depends on that border's corners only, see new_corner).
  struct RightColumn {
    std::uint64_t frame = 0;
    int x1 = -1, y0 = -1;
    std::int32_t triangle = -1;
    std::array<Vector3f, kCorners> color;
  };
  thread_local RightColumn left;
  if (left.frame == frame_serial_ && left.x1 == x0 && left.y0 == y0 && left.triangle == id) {
    for (int cy = 0; cy <= rows; ++cy) {
      cache.plane[cy * kCorners] = plane.source;
      cache.color[cy * kCorners] = left.color[cy];
    }
  }
  // A whole tile whose four corners agree is smooth: every corner inside it would come out as
  // their bilinear blend (the 16 px and 8 px corners from agreeing cells, the odd ones as
  // means of those), so the inner ones are blended straight from the four. The left and right
  // columns, which the tiles beside it share (see RightColumn), still follow the rule they do
  // there. The top and bottom rows are blended too: a tile above or below that is not smooth
  // reaches the same values by the rule's steps, which may round an ulp apart (the seam is
  // 1e-7 of the light; it does not depend on which thread draws which tile).
  bool smooth = false;
  if (tile_corners_ && columns == kCorners - 1 && rows == kCorners - 1) {
    constexpr int kLast = kCorners - 1;
    const Vector3f c00 = corner(cache, plane, x0, y0, 0, 0);
    const Vector3f c10 = corner(cache, plane, x0, y0, kLast, 0);
    const Vector3f c01 = corner(cache, plane, x0, y0, 0, kLast);
    const Vector3f c11 = corner(cache, plane, x0, y0, kLast, kLast);
    smooth = corners_agree(c00, c10, c01, c11, kTileCellTolerance);
    if (smooth) {
      for (int cy = 0; cy <= kLast; ++cy) {
        corner(cache, plane, x0, y0, 0, cy);
        corner(cache, plane, x0, y0, kLast, cy);
        const float ty = static_cast<float>(cy) / kLast;
        const Vector3f row_left = (1 - ty) * c00 + ty * c01;
        const Vector3f row_right = (1 - ty) * c10 + ty * c11;
        for (int cx = 1; cx < kLast; ++cx) {
          const float tx = static_cast<float>(cx) / kLast;
          const int slot = cy * kCorners + cx;
          cache.color[slot] = (1 - tx) * row_left + tx * row_right;
          cache.plane[slot] = plane.source;
        }
      }
    }
  }
  for (int cy = 0; cy <= rows && !smooth; ++cy) {
    for (int cx = 0; cx <= columns; ++cx) corner(cache, plane, x0, y0, cx, cy);
  }
  left.frame = frame_serial_;
  left.x1 = columns == kTileSize / kBlock ? x1 : -1;
  left.y0 = y0;
  left.triangle = id;
  for (int cy = 0; cy <= rows; ++cy) left.color[cy] = cache.color[cy * kCorners + columns];
}

void StudioPlanes::write_tile(const PlaneCorners& cache, const ScreenTriangle& plane, int x0,
                              int y0, int x1, int y1) const {
  dslr::LinearFrame& frame = shader_.frame();
  const int width = frame.width;
  // 1/z is affine over the plane, so in every pixel the nearest of the four samples is the
  // one furthest along its gradient: one sample per pixel, eight pixels at a time.
  int near_sample = 0;
  for (int k = 1; k < kSamples; ++k) {
    auto along = [&](int j) {
      return plane.inv_z_plane[0] * kSampleX[j] + plane.inv_z_plane[1] * kSampleY[j];
    };
    if (along(k) > along(near_sample)) near_sample = k;
  }
  const Float8 pixel_x = kTexelCentres - 0.5f;  // 0, 1, ..., 7
  const Float8 infinity = Float8{} + std::numeric_limits<float>::infinity();
  for (int py = y0; py < y1; ++py) {
    const int cy = (py - y0) / kBlock;
    const float fy = ((py - y0) % kBlock + 0.5f) / kBlock;
    float* rgb = &frame.rgb[3 * (static_cast<std::size_t>(py) * width + x0)];
    float* depth = &frame.depth_m[static_cast<std::size_t>(py) * width + x0];
    std::fill_n(&frame.mask[static_cast<std::size_t>(py) * width + x0], x1 - x0, 0);
    // Whole blocks: their four pixels' twelve values, blended from the two corners' colours
    // repeated across three four-lane registers (the per-pixel arithmetic of the loop below).
    const int whole_blocks = (x1 - x0) / kBlock;
    static_assert(kBlock == 4, "a block's twelve values are three four-lane registers");
    static constexpr Float4 kWeight[3] = {{0.125f, 0.125f, 0.125f, 0.375f},
                                          {0.375f, 0.375f, 0.625f, 0.625f},
                                          {0.625f, 0.875f, 0.875f, 0.875f}};
    // An RGB corner's channels in the order the block's three vectors of four hold them.
    auto rotations = [](Float4 v) {
      return std::array<Float4, 3>{__builtin_shufflevector(v, v, 0, 1, 2, 0),
                                   __builtin_shufflevector(v, v, 1, 2, 0, 1),
                                   __builtin_shufflevector(v, v, 2, 0, 1, 2)};
    };
    // The corners' rows read directly: loading four floats just stored as three stalls.
    const float* upper_row = cache.color[cy * kCorners].data();
    const float* lower_row = cache.color[(cy + 1) * kCorners].data();
    auto edge_at = [&](int cx) {
      return fy * load4(lower_row + 3 * cx) + (1 - fy) * load4(upper_row + 3 * cx);
    };
    for (int cx = 0; cx < whole_blocks; ++cx) {
      const std::array<Float4, 3> from = rotations(edge_at(cx)), to = rotations(edge_at(cx + 1));
      for (int k = 0; k < 3; ++k) {
        store4(rgb + 3 * kBlock * cx + 4 * k, kWeight[k] * to[k] + (1 - kWeight[k]) * from[k]);
      }
    }
    // A last, partial block (the canvas's right edge): pixel by pixel.
    for (int px = x0 + kBlock * whole_blocks; px < x1; ++px) {
      const int cx = (px - x0) / kBlock;
      const float fx = ((px - x0) % kBlock + 0.5f) / kBlock;
      const Float4 left = edge_at(cx), right = edge_at(cx + 1);
      const Float4 color = fx * right + (1 - fx) * left;
      float* out = rgb + 3 * (px - x0);
      for (int c = 0; c < 3; ++c) out[c] = color[c];
    }
    // The nearest sample's 1/z, as the visibility pass computes it.
    const float iz_row = plane.inv_z_plane[1] * (static_cast<float>(py) + kSampleY[near_sample]);
    for (int px = x0; px < x1; px += 8) {
      const Float8 sx = (static_cast<float>(px) + pixel_x) + kSampleX[near_sample];
      const Float8 nearest = plane.inv_z_plane[0] * sx + iz_row + plane.inv_z_plane[2];
      const Float8 z = nearest > 0 ? 1 / nearest : infinity;
      if (x1 - px >= 8) {
        std::memcpy(depth + (px - x0), &z, sizeof z);  // a fixed size: no library call
      } else {
        std::memcpy(depth + (px - x0), &z, (x1 - px) * sizeof(float));
      }
    }
  }
}

bool StudioPlanes::fill_tile(int x0, int y0, int x1, int y1, std::int32_t id) const {
  const ScreenTriangle& plane = shader_.screen_triangle(id);
  if (!shader_.use_blocks() || !shader_.plain_studio(plane)) return false;
  PlaneCorners cache;
  const int columns = (x1 - x0 + kBlock - 1) / kBlock, rows = (y1 - y0 + kBlock - 1) / kBlock;
  tile_corners_of(cache, plane, id, x0, y0, x1, columns, rows);
  write_tile(cache, plane, x0, y0, x1, y1);
  return true;
}

}  // namespace rigc::raster
