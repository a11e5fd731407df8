// Internal to the rasterizer: visibility in tiles of kTileSize pixels, every screen triangle of a
// tile's bin tested at one sample per pixel or four, the nearest kept per sample. Templates,
// inline: the callers' per-tile work is inlined into the loop over tiles.
#pragma once

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <array>
#include <cstdint>
#include <cstring>
#include <iterator>
#include <type_traits>

#include "dslr/frame.h"
#include "raster/raster_common.h"
#include "raster/screen_setup.h"

namespace rigc::raster {
namespace tile_raster {

// A tile's pixels x0 .. x1 - 1, y0 .. y1 - 1.
struct TileBox {
  int x0, y0, x1, y1;
};

// The screen triangle whose plane alone shows in the tile's box of samples, or -1. One convex
// plane alone may show: the nearest triangle with a corner of the box inside it, together with
// the triangles of its convex face (face_of: the two of a quad, the strips of a disc), when each
// corner lies inside one of them (a convex polygon holding the four corners holds the box) and
// every other triangle's plane lies behind it at all four corners (1/z is affine: then at every
// sample too). The studio's planes overlap: the floor runs on behind the green screen, the
// turntable's stand behind its disc.
template <int Samples, typename FaceOf>
[[gnu::always_inline]] inline std::int32_t uniform_plane(const ScreenSetup& setup, int tile,
                                                         const TileBox& box,
                                                         const FaceOf& face_of) {
  // Each triangle against the box of the tile's samples: inside all three edges at the four
  // corners (covers), outside one edge at all four (misses), or neither. The planes are affine,
  // so the corners decide; a margin keeps rounding out.
  constexpr float kMargin = 1e-4f, kBehindMargin = 1e-3f;
  const float bx0 = box.x0 + (Samples == 1 ? 0.5f : 0.125f);
  const float bx1 = box.x1 - 1 + (Samples == 1 ? 0.5f : 0.875f);
  const float by0 = box.y0 + (Samples == 1 ? 0.5f : 0.125f);
  const float by1 = box.y1 - 1 + (Samples == 1 ? 0.5f : 0.875f);
  const Float4 cx = {bx0, bx1, bx0, bx1}, cy = {by0, by0, by1, by1};
  struct Seen {
    std::int32_t id, face;
    Float4 inv_z;
    Int4 in;
  };
  constexpr int kMaxSeen = 32;  // a busier bin is the object's, never one plane
  std::array<Seen, kMaxSeen> seen;
  int seen_count = 0, front = -1;
  float front_inv_z = 0;
  auto all = [](Int4 m) { return m[0] && m[1] && m[2] && m[3]; };
  for (std::int32_t i = setup.tile_start[tile]; i < setup.tile_start[tile + 1]; ++i) {
    const ScreenTriangle& s = setup.tris[setup.tile_tris[i]];
    const Float4 w0 = s.w0_plane[0] * cx + s.w0_plane[1] * cy + s.w0_plane[2];
    const Float4 w1 = s.w1_plane[0] * cx + s.w1_plane[1] * cy + s.w1_plane[2];
    const Float4 w2 = 1 - (w0 + w1);
    const Int4 out0 = w0 < -kMargin, out1 = w1 < -kMargin, out2 = w2 < -kMargin;
    if (all(out0) || all(out1) || all(out2)) continue;  // misses
    if (seen_count == kMaxSeen) return -1;
    const Int4 in = (w0 >= kMargin) & (w1 >= kMargin) & (w2 >= kMargin);
    const Float4 inv_z = s.inv_z_plane[0] * cx + s.inv_z_plane[1] * cy + s.inv_z_plane[2];
    seen[seen_count] = {setup.tile_tris[i], face_of(s), inv_z, in};
    const float centre_inv_z = 0.5f * (inv_z[0] + inv_z[3]);
    if ((in[0] || in[1] || in[2] || in[3]) && (front < 0 || centre_inv_z > front_inv_z)) {
      front = seen_count;
      front_inv_z = centre_inv_z;
    }
    ++seen_count;
  }
  if (front < 0) return -1;
  const Seen& plane = seen[front];
  // Behind by more than float rounding can move a sample's 1/z.
  const Float4 behind = plane.inv_z - kBehindMargin * plane.inv_z;
  Int4 covered = plane.in;
  bool alone = plane.inv_z[0] > 0 && plane.inv_z[3] > 0;
  for (int k = 0; k < seen_count && alone; ++k) {
    if (k == front) continue;
    if (plane.face >= 0 && seen[k].face == plane.face) {
      covered |= seen[k].in;
    } else {
      alone = all(seen[k].inv_z < behind);
    }
  }
  return alone && all(covered) ? plane.id : -1;
}

// A tile's per-sample buffers: the sample of pixel (px, py) at
// ((py - y0)·kTileSize + px - x0)·Samples holds the nearest 1/z and screen triangle (-1: none).
template <int Samples>
struct TileSamples {
  alignas(64) float inv_z[kTileSize * kTileSize * Samples];
  alignas(64) std::int32_t tri[kTileSize * kTileSize * Samples];

  void clear() {
    std::fill(std::begin(inv_z), std::end(inv_z), 0.0f);
    std::fill(std::begin(tri), std::end(tri), -1);
  }
};

// Lane offsets from the pixel (Samples 4) or from the first of four pixels (Samples 1).
template <int Samples>
inline constexpr Float4 kLaneX =
    Samples == 1 ? Float4{0.5f, 1.5f, 2.5f, 3.5f}
                 : Float4{kSampleX[0], kSampleX[1], kSampleX[2], kSampleX[3]};
template <int Samples>
inline constexpr Float4 kLaneY =
    Samples == 1 ? Float4{0.5f, 0.5f, 0.5f, 0.5f}
                 : Float4{kSampleY[0], kSampleY[1], kSampleY[2], kSampleY[3]};
// Two pixels' samples on eight lanes.
inline constexpr Float8 kLaneX8 = {kSampleX[0],     kSampleX[1],     kSampleX[2],
                                   kSampleX[3],     1 + kSampleX[0], 1 + kSampleX[1],
                                   1 + kSampleX[2], 1 + kSampleX[3]};
inline constexpr Float8 kLaneY8 = {kSampleY[0], kSampleY[1], kSampleY[2], kSampleY[3],
                                   kSampleY[0], kSampleY[1], kSampleY[2], kSampleY[3]};

// One screen triangle's samples inside pixels px0 .. px1, py0 .. py1 of the tile at (x0, y0),
// tested into `samples`. Four samples are tested at once: a pixel's four, or four neighbouring
// pixel centres. Each lane evaluates the planes with the same expression as a scalar pass would,
// so coverage and depth ties come out the same. Every step stores, hit or not: a branch on "any
// hit" mispredicts at each row's two edges (the stores go to the tile's own buffers, in L1).
template <int Samples>
struct TriangleSamples {
  static constexpr int kStepX = Samples == 1 ? 4 : 1;  // pixels per group of four lanes

  const ScreenTriangle& s;
  int x0, y0, px0, px1, py0, py1;
  float* inv_z;
  std::int32_t* tri;
  Int4 id4;
  Int8 id8;

  [[gnu::always_inline]] int base(int px, int py) const {
    return ((py - y0) * kTileSize + (px - x0)) * Samples;
  }

  // Whether the triangle covers the whole box of samples (the studio's big ones): the planes
  // are affine, so the box's corners decide, with a margin for rounding.
  [[gnu::always_inline]] bool covers_box() const {
    constexpr float kMargin = 1e-4f;
    const float bx0 = px0 + (Samples == 1 ? 0.5f : 0.125f);
    const float bx1 = px1 + (Samples == 1 ? 0.5f + kStepX - 1 : 0.875f);
    const float by0 = py0 + (Samples == 1 ? 0.5f : 0.125f);
    const float by1 = py1 + (Samples == 1 ? 0.5f : 0.875f);
    const Float4 cx = {bx0, bx1, bx0, bx1}, cy = {by0, by0, by1, by1};
    const Float4 w0 = s.w0_plane[0] * cx + s.w0_plane[1] * cy + s.w0_plane[2];
    const Float4 w1 = s.w1_plane[0] * cx + s.w1_plane[1] * cy + s.w1_plane[2];
    const Int4 inside = (w0 >= kMargin) & (w1 >= kMargin) & (w0 + w1 <= 1 - kMargin);
    return inside[0] && inside[1] && inside[2] && inside[3];
  }

  // A triangle that covers the box needs only the depth test.
  [[gnu::always_inline]] void depth_test() {
    for (int py = py0; py <= py1; ++py) {
      const Float4 sy = static_cast<float>(py) + kLaneY<Samples>;
      const Float4 iz_row = s.inv_z_plane[1] * sy;
      for (int px = px0; px <= px1; px += kStepX) {
        const Float4 sx = static_cast<float>(px) + kLaneX<Samples>;
        const Float4 z = s.inv_z_plane[0] * sx + iz_row + s.inv_z_plane[2];
        const Float4 nearest = load4(inv_z + base(px, py));
        const Int4 hit = z > nearest;
        store4(inv_z + base(px, py), hit ? z : nearest);
        store4(tri + base(px, py), hit ? id4 : load4(tri + base(px, py)));
      }
    }
  }

  // Four lanes at (px, py): edge and depth tests, nearest depth and triangle kept.
  [[gnu::always_inline]] void test4(int px, int py, Float4 w0_row, Float4 w1_row, Float4 iz_row) {
    const Float4 sx = static_cast<float>(px) + kLaneX<Samples>;
    const Float4 w0 = s.w0_plane[0] * sx + w0_row + s.w0_plane[2];
    const Float4 w1 = s.w1_plane[0] * sx + w1_row + s.w1_plane[2];
    const Float4 z = s.inv_z_plane[0] * sx + iz_row + s.inv_z_plane[2];
    const Float4 nearest = load4(inv_z + base(px, py));
    const Int4 hit = (w0 >= 0) & (w1 >= 0) & (w0 + w1 <= 1) & (z > nearest);
    store4(inv_z + base(px, py), hit ? z : nearest);
    store4(tri + base(px, py), hit ? id4 : load4(tri + base(px, py)));
  }

  // Four lanes a step.
  [[gnu::always_inline]] void test_rows() {
    for (int py = py0; py <= py1; ++py) {
      const Float4 sy = static_cast<float>(py) + kLaneY<Samples>;
      const Float4 w0_row = s.w0_plane[1] * sy;
      const Float4 w1_row = s.w1_plane[1] * sy;
      const Float4 iz_row = s.inv_z_plane[1] * sy;
      for (int px = px0; px <= px1; px += kStepX) test4(px, py, w0_row, w1_row, iz_row);
    }
  }

  // Four samples a pixel: two pixels' eight samples per step (one 8-lane register), the odd last
  // one on four lanes. The lanes of the second pixel compute px + (1 + offset), which is exactly
  // (px + 1) + offset in floats: the same coverage and depths.
  [[gnu::always_inline]] void test_pixel_pairs() {
    for (int py = py0; py <= py1; ++py) {
      const Float8 sy = static_cast<float>(py) + kLaneY8;
      const Float8 w0_row = s.w0_plane[1] * sy;
      const Float8 w1_row = s.w1_plane[1] * sy;
      const Float8 iz_row = s.inv_z_plane[1] * sy;
      int px = px0;
      for (; px + 1 <= px1; px += 2) {
        const Float8 sx = static_cast<float>(px) + kLaneX8;
        const Float8 w0 = s.w0_plane[0] * sx + w0_row + s.w0_plane[2];
        const Float8 w1 = s.w1_plane[0] * sx + w1_row + s.w1_plane[2];
        const Float8 z = s.inv_z_plane[0] * sx + iz_row + s.inv_z_plane[2];
        Float8 nearest;
        std::memcpy(&nearest, inv_z + base(px, py), sizeof(nearest));
        const Int8 hit = (w0 >= 0) & (w1 >= 0) & (w0 + w1 <= 1) & (z > nearest);
        Int8 ids;
        std::memcpy(&ids, tri + base(px, py), sizeof(ids));
        const Float8 new_z = hit ? z : nearest;
        const Int8 new_ids = hit ? id8 : ids;
        std::memcpy(inv_z + base(px, py), &new_z, sizeof(new_z));
        std::memcpy(tri + base(px, py), &new_ids, sizeof(new_ids));
      }
      if (px == px1) {
        const Float4 sy4 = static_cast<float>(py) + kLaneY<Samples>;
        test4(px, py, s.w0_plane[1] * sy4, s.w1_plane[1] * sy4, s.inv_z_plane[1] * sy4);
      }
    }
  }

  [[gnu::always_inline]] void run() {
    if (covers_box()) {
      depth_test();
    } else if constexpr (Samples == kSamples) {
      test_pixel_pairs();
    } else {
      test_rows();
    }
  }
};

// Every triangle of the tile's bin into `samples`.
template <int Samples>
[[gnu::always_inline]] inline void rasterize_bin(const ScreenSetup& setup, int tile,
                                                 const TileBox& box,
                                                 TileSamples<Samples>& samples) {
  const auto [x0, y0, x1, y1] = box;
  samples.clear();
  const std::int32_t* bin = setup.tile_tris.data();
  for (std::int32_t i = setup.tile_start[tile]; i < setup.tile_start[tile + 1]; ++i) {
    const std::int32_t id = bin[i];
    const ScreenTriangle& s = setup.tris[id];
    // Groups of four pixel centres start at multiples of four inside the tile; lanes outside the
    // triangle's box fail its edge tests, lanes past the canvas are never resolved.
    const int px0 =
        Samples == 1 ? x0 + ((std::max<int>(x0, s.x0) - x0) & ~3) : std::max<int>(x0, s.x0);
    const int px1 = std::min<int>(x1 - 1, s.x1);
    const int py0 = std::max<int>(y0, s.y0), py1 = std::min<int>(y1 - 1, s.y1);
    TriangleSamples<Samples>{
        s, x0, y0, px0, px1, py0, py1, samples.inv_z, samples.tri, Int4{} + id, Int8{} + id}
        .run();
  }
}

}  // namespace tile_raster

// Visibility in tiles with `Samples` samples per pixel (1: the pixel centre; 4: a rotated grid),
// then resolve_tile(x0, y0, x1, y1, inv_z, tri) for every tile, with the samples of pixel
// (px, py) at ((py - y0)·kTileSize + px - x0)·Samples (tri -1: nothing there).
// uniform_tile(x0, y0, x1, y1, id) is offered each tile where only the plane of screen triangle
// `id` shows (the studio's big planes; see tile_raster::uniform_plane): returning true, it has
// written the tile itself and the samples are skipped. face_of(triangle) names the convex planar
// face a triangle belongs to (-1: none), so that the triangles of one face may cover a tile
// together; nullptr: no tile is offered (the callers that shade every pixel themselves).
template <int Samples, typename FaceOf, typename UniformTile, typename ResolveTile>
void rasterize_tiles(const ScreenSetup& setup, const dslr::Intrinsics& canvas,
                     const FaceOf& face_of, const UniformTile& uniform_tile,
                     const ResolveTile& resolve_tile) {
  static_assert(Samples == 1 || Samples == kSamples);
  static_assert(kTileSize % 4 == 0);
  tbb::parallel_for(tbb::blocked_range<int>(0, setup.tiles_x * setup.tiles_y, 4),
                    [&](const tbb::blocked_range<int>& range) {
                      tile_raster::TileSamples<Samples> samples;
                      for (int tile = range.begin(); tile != range.end(); ++tile) {
                        const int tx = tile % setup.tiles_x, ty = tile / setup.tiles_x;
                        const int x0 = tx * kTileSize, y0 = ty * kTileSize;
                        const int x1 = std::min(x0 + kTileSize, canvas.width);
                        const int y1 = std::min(y0 + kTileSize, canvas.height);
                        const tile_raster::TileBox box = {x0, y0, x1, y1};
                        if constexpr (!std::is_same_v<FaceOf, std::nullptr_t>) {
                          const std::int32_t plane =
                              tile_raster::uniform_plane<Samples>(setup, tile, box, face_of);
                          if (plane >= 0 && uniform_tile(x0, y0, x1, y1, plane)) continue;
                        }
                        tile_raster::rasterize_bin<Samples>(setup, tile, box, samples);
                        resolve_tile(x0, y0, x1, y1, samples.inv_z, samples.tri);
                      }
                    });
}

// resolve(px, py, inv_z[Samples], tri[Samples]) for every pixel of every tile.
template <int Samples, typename Resolve>
void rasterize_pixels(const ScreenSetup& setup, const dslr::Intrinsics& canvas,
                      const Resolve& resolve) {
  rasterize_tiles<Samples>(
      setup, canvas, nullptr, [](int, int, int, int, std::int32_t) { return false; },
      [&](int x0, int y0, int x1, int y1, const float* inv_z, const std::int32_t* tri) {
        for (int py = y0; py < y1; ++py) {
          for (int px = x0; px < x1; ++px) {
            const int base = ((py - y0) * kTileSize + (px - x0)) * Samples;
            resolve(px, py, inv_z + base, tri + base);
          }
        }
      });
}

}  // namespace rigc::raster
