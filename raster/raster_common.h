// Internal to the rasterizer: the sampling constants, the vector types, a screen triangle's
// planes and the binning of triangles into tiles or bands, shared by the shadow maps, the screen
// setup and the tile raster.
#pragma once

#include <tbb/parallel_for.h>

#include <Eigen/Core>
#include <algorithm>
#include <array>
#include <chrono>
#include <cstdint>
#include <cstring>
#include <numbers>
#include <vector>

#include "dslr/simd.h"
#include "io/elapsed.h"

namespace rigc::raster {

using Eigen::Matrix3f;
using Eigen::Vector2f;
using Eigen::Vector3f;
using Clock = std::chrono::steady_clock;

inline constexpr int kTileSize = 32;
inline constexpr int kSamples = 4;
// Rotated-grid sample offsets inside a pixel: good edge anti-aliasing for four samples.
inline constexpr float kSampleX[kSamples] = {0.375f, 0.875f, 0.125f, 0.625f};
inline constexpr float kSampleY[kSamples] = {0.125f, 0.375f, 0.625f, 0.875f};
inline constexpr float kNear = 0.01f;
inline constexpr float kPi = std::numbers::pi_v<float>;

using io::ms_since;

// Eight floats or lane masks (a shadow map's texels, two pixels' samples), four (one pixel's
// samples, or four pixel centres in a row).
using Float8 = simd::F32x8;
using Int8 = simd::I32x8;
using Float4 = simd::F32x4;
using Int4 = simd::I32x4;
inline constexpr Float8 kTexelCentres = {0.5f, 1.5f, 2.5f, 3.5f, 4.5f, 5.5f, 6.5f, 7.5f};

using simd::load4;
inline Int4 load4(const std::int32_t* p) {
  Int4 v;
  std::memcpy(&v, p, sizeof(v));
  return v;
}
inline void store4(float* p, Float4 v) {
  std::memcpy(p, &v, sizeof(v));
}
inline void store4(std::int32_t* p, Int4 v) {
  std::memcpy(p, &v, sizeof(v));
}

// A triangle after clipping and projection, 64 bytes: a million of them are set up per frame,
// so their size is memory traffic. Attributes are looked up in the source triangle through the
// barycentric coordinates each corner has there (identity unless the triangle was clipped).
struct ScreenTriangle {
  // Planes in pixel coordinates, value = a·x + b·y + c: the barycentrics w0, w1 and 1/z.
  std::array<float, 3> w0_plane, w1_plane, inv_z_plane;
  std::array<float, 3> inv_z;  // 1 / camera z at the corners
  // Pixels the bounding box touches on the canvas, inclusive.
  std::uint16_t x0, y0, x1, y1;
  std::int32_t source;   // triangle index; object triangles first, then studio
  std::int32_t clipped;  // -1, or index of the corners' source barycentrics in ScreenSetup
};
static_assert(sizeof(ScreenTriangle) == 64);

// The planes of a screen triangle with corners `screen`, given 1 / (twice its signed area).
inline void compute_planes(ScreenTriangle& t, const std::array<Vector2f, 3>& screen,
                           float inv_area) {
  auto edge_plane = [&](const Vector2f& a, const Vector2f& b) {
    return std::array<float, 3>{-(b.y() - a.y()) * inv_area, (b.x() - a.x()) * inv_area,
                                ((b.y() - a.y()) * a.x() - (b.x() - a.x()) * a.y()) * inv_area};
  };
  t.w0_plane = edge_plane(screen[1], screen[2]);
  t.w1_plane = edge_plane(screen[2], screen[0]);
  // w2 = 1 - w0 - w1, so 1/z = iz2 + w0·(iz0 - iz2) + w1·(iz1 - iz2).
  const float d0 = t.inv_z[0] - t.inv_z[2], d1 = t.inv_z[1] - t.inv_z[2];
  for (int i = 0; i < 3; ++i) t.inv_z_plane[i] = t.w0_plane[i] * d0 + t.w1_plane[i] * d1;
  t.inv_z_plane[2] += t.inv_z[2];
}

inline float edge(const Vector2f& a, const Vector2f& b, float px, float py) {
  return (b.x() - a.x()) * (py - a.y()) - (b.y() - a.y()) * (px - a.x());
}

// Perspective-correct barycentrics of the screen triangle at (px, py), unclamped.
inline Vector3f screen_bary(const ScreenTriangle& t, float px, float py) {
  const float w0 = t.w0_plane[0] * px + t.w0_plane[1] * py + t.w0_plane[2];
  const float w1 = t.w1_plane[0] * px + t.w1_plane[1] * py + t.w1_plane[2];
  const float w2 = 1 - w0 - w1;
  Vector3f p(w0 * t.inv_z[0], w1 * t.inv_z[1], w2 * t.inv_z[2]);
  const float sum = p.sum();
  return sum != 0 ? Vector3f(p / sum) : Vector3f(1.0f / 3, 1.0f / 3, 1.0f / 3);
}

// Items (triangles) sorted into cells (tiles, bands): cell c holds
// items[start[c] .. start[c + 1]), in item order, so ties resolve as in a serial pass.
struct CellBins {
  std::vector<std::int32_t> start;
  std::vector<std::int32_t> items;
};

// cells_of(i, fn) calls fn(cell) for every cell item i touches. Counting per block of items and
// cell, then filling, both in parallel.
template <typename CellsOf>
CellBins bin_items(int item_count, int cell_count, const CellsOf& cells_of) {
  CellBins bins;
  const int blocks = std::clamp(item_count / 16384, 1, 64);
  auto block_begin = [&](int b) {
    return static_cast<int>(static_cast<std::int64_t>(item_count) * b / blocks);
  };
  std::vector<std::int32_t> cursor(static_cast<size_t>(blocks) * cell_count, 0);
  tbb::parallel_for(0, blocks, [&](int b) {
    std::int32_t* count = cursor.data() + static_cast<size_t>(b) * cell_count;
    for (int i = block_begin(b); i < block_begin(b + 1); ++i) {
      cells_of(i, [&](int cell) { ++count[cell]; });
    }
  });
  bins.start.resize(cell_count + 1);
  std::int32_t running = 0;
  for (int cell = 0; cell < cell_count; ++cell) {
    bins.start[cell] = running;
    for (int b = 0; b < blocks; ++b) {
      std::int32_t& slot = cursor[static_cast<size_t>(b) * cell_count + cell];
      const std::int32_t count = slot;
      slot = running;
      running += count;
    }
  }
  bins.start[cell_count] = running;
  bins.items.resize(running);
  tbb::parallel_for(0, blocks, [&](int b) {
    std::int32_t* next = cursor.data() + static_cast<size_t>(b) * cell_count;
    for (int i = block_begin(b); i < block_begin(b + 1); ++i) {
      cells_of(i, [&](int cell) { bins.items[next[cell]++] = i; });
    }
  });
  return bins;
}

}  // namespace rigc::raster
