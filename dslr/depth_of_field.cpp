#include "dslr/depth_of_field.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <array>
#include <atomic>
#include <cmath>
#include <cstring>
#include <limits>
#include <numbers>
#include <span>
#include <type_traits>
#include <utility>

#include "dslr/buffer_pool.h"
#include "dslr/depth_of_field_level.h"
#include "dslr/optics.h"
#include "dslr/simd.h"

namespace rigc::dslr {

void record_tile_ranges(const float* rgb, const float* depth_m, int width, int x0, int y0, int x1,
                        int y1, TileRanges& ranges) {
  constexpr int kTile = TileRanges::kTile;
  static_assert(kTile == 16, "a tile row is two registers of depth and six of colour");
  using simd::F32x8;
  constexpr float inf = std::numeric_limits<float>::infinity();
  auto lower = [](F32x8 a, F32x8 b) { return b < a ? b : a; };  // std::min, lane by lane
  auto upper = [](F32x8 a, F32x8 b) { return a < b ? b : a; };  // std::max
  for (int ty0 = y0; ty0 < y1; ty0 += kTile) {
    for (int tx0 = x0; tx0 < x1; tx0 += kTile) {
      const int count = std::min(kTile, x1 - tx0);
      // Per lane (depth) and per value (colour) over the tile's rows, in registers, then
      // folded. A tile cut by the frame's right edge reads copies of its rows, padded.
      F32x8 z_lo[2], z_hi[2], c_lo[6], c_hi[6];
      for (auto& v : z_lo) v = F32x8{} + inf;
      for (auto& v : z_hi) v = F32x8{};
      for (auto& v : c_lo) v = F32x8{} + inf;
      for (auto& v : c_hi) v = F32x8{} - inf;
      for (int y = ty0; y < std::min(y1, ty0 + kTile); ++y) {
        const float* z_row = depth_m + static_cast<std::size_t>(y) * width + tx0;
        const float* c_row = rgb + 3 * (static_cast<std::size_t>(y) * width + tx0);
        std::array<float, kTile> z_lo_pad, z_hi_pad;
        std::array<float, 3 * kTile> lo_pad, hi_pad;
        const float *z_lo_values = z_row, *z_hi_values = z_row;
        const float *lo_values = c_row, *hi_values = c_row;
        if (count < kTile) {
          // Pads that move neither end: +inf for the smallest; for the largest depth the least
          // positive float (a depth must be > 0 to stay itself) and -inf for the colour.
          z_lo_pad.fill(inf);
          z_hi_pad.fill(std::numeric_limits<float>::denorm_min());
          lo_pad.fill(inf);
          hi_pad.fill(-inf);
          std::copy_n(z_row, count, z_lo_pad.begin());
          std::copy_n(z_row, count, z_hi_pad.begin());
          std::copy_n(c_row, 3 * count, lo_pad.begin());
          std::copy_n(c_row, 3 * count, hi_pad.begin());
          z_lo_values = z_lo_pad.data();
          z_hi_values = z_hi_pad.data();
          lo_values = lo_pad.data();
          hi_values = hi_pad.data();
        }
        auto background_inf = [](F32x8 depth) {  // unknown depth: background
          return depth > 0.0f ? depth : F32x8{} + inf;
        };
        for (int k = 0; k < 2; ++k) {
          z_lo[k] = lower(z_lo[k], background_inf(simd::load8(z_lo_values + 8 * k)));
          z_hi[k] = upper(z_hi[k], background_inf(simd::load8(z_hi_values + 8 * k)));
        }
        for (int k = 0; k < 6; ++k) {
          c_lo[k] = lower(c_lo[k], simd::load8(lo_values + 8 * k));
          c_hi[k] = upper(c_hi[k], simd::load8(hi_values + 8 * k));
        }
      }
      const std::size_t t = static_cast<std::size_t>(ty0 / kTile) * ranges.tiles_x + tx0 / kTile;
      float near = inf, far = 0;
      for (int k = 0; k < kTile; ++k) {
        near = std::min(near, z_lo[k / 8][k % 8]);
        far = std::max(far, z_hi[k / 8][k % 8]);
      }
      ranges.near_m[t] = near;
      ranges.far_m[t] = far;
      for (int c = 0; c < 3; ++c) {
        float lo = inf, hi = -inf;
        for (int k = c; k < 3 * kTile; k += 3) {
          lo = std::min(lo, c_lo[k / 8][k % 8]);
          hi = std::max(hi, c_hi[k / 8][k % 8]);
        }
        ranges.radiance[6 * t + c] = lo;
        ranges.radiance[6 * t + 3 + c] = hi;
      }
    }
  }
}

namespace dof {

// The values the coarse levels below a w x h frame at `level` take for their outputs: three per
// pixel of each half-size frame down to kMaxCoarseLevel.
std::size_t coarse_output_values(int w, int h, int level) {
  std::size_t total = 0;
  for (int k = level; k < kMaxCoarseLevel; ++k) {
    w = (w + 1) / 2;
    h = (h + 1) / 2;
    total += 3 * static_cast<std::size_t>(w) * h;
  }
  return total;
}

// The values an in-place call at the top level needs in its spare memory: the half-size input
// (four per half-size pixel) and the levels' outputs after it.
std::size_t in_place_spare_values(int w, int h) {
  return 4 * (static_cast<std::size_t>(w + 1) / 2) * ((h + 1) / 2) + coarse_output_values(w, h, 0);
}

void keep_input(const LevelInput& in) {
  const bool in_place = in.rgb.data() == in.out.data() && in.rgb.size() == in.out.size();
  if (!in_place) std::copy(in.rgb.begin(), in.rgb.end(), in.out.begin());
}

DepthOfFieldLevel::DepthOfFieldLevel(const LevelInput& in)
    : in_(in),
      w_(in.canvas.width),
      h_(in.canvas.height),
      in_place_(in.rgb.data() == in.out.data() && in.rgb.size() == in.out.size()),
      levels_values_(coarse_output_values(w_, h_, in.level)),
      tiles_x_((w_ + kTile - 1) / kTile),
      tiles_y_((h_ + kTile - 1) / kTile),
      set_(tap_set()) {
  const double f = in.camera.focal_length_m, f_number = in.camera.aperture_f_number;
  radius_at_.radius_at_infinity = static_cast<float>(
      0.5 *
      coc_in_image_m(f, f_number, in.focus_distance_m, std::numeric_limits<double>::infinity()) *
      in.canvas.fx / f);
  radius_at_.focus = static_cast<float>(in.focus_distance_m);
  for (int k = 0; k < in.level; ++k) radius_at_.removed_radius_sq += std::ldexp(1.0f, -2 * k);
  // The coarse levels' discs are 2 px and more, and what they take off was set with the ramps in.
  if (in.level > 0) radius_at_.matched = nullptr;
}

void DepthOfFieldLevel::run() {
  measure_tiles();
  if (spread_reach() <= 0.5f) {  // everything is sharp
    keep_input(in_);
    return;
  }
  mark_flat_and_one_surface_tiles();
  mark_coarse_tiles();
  if (any_coarse_) blur_coarse_tiles_at_half_size();
  plan_strips();
  if (in_place_) keep_halos();
  blur_strips();
}

// Each tile's nearest and furthest depth and its smallest and largest value per channel: the
// renderer's ranges where it handed them over (the top level only: below it the frame is the
// half-size one made here); otherwise each row of tiles is scanned for them. From those, each
// tile's largest and smallest disc.
void DepthOfFieldLevel::measure_tiles() {
  static_assert(TileRanges::kTile == kTile);
  ranges_ = in_.level == 0 ? in_.options.tile_ranges : nullptr;
  if (ranges_ == nullptr || !ranges_->fits(w_, h_)) {
    scanned_.resize_for(w_, h_);
    tbb::parallel_for(0, tiles_y_, [&](int ty) {
      record_tile_ranges(in_.rgb.data(), in_.depth_m.data(), w_, 0, ty * kTile, w_,
                         std::min(h_, (ty + 1) * kTile), scanned_);
    });
    ranges_ = &scanned_;
  }
  // The radius falls towards the focus distance and grows away from it on both sides, so a
  // tile's depth range gives its smallest and largest disc without a radius per pixel.
  const std::size_t tiles = static_cast<std::size_t>(tiles_x_) * tiles_y_;
  tile_max_.assign(tiles, 0.5f);
  tile_min_.assign(tiles, static_cast<float>(kMaxCocRadiusPx));
  const BlurRadius radius_at = radius_at_;
  const float focus = radius_at.focus;
  for (std::size_t t = 0; t < tiles; ++t) {
    const float near = ranges_->near_m[t], far = ranges_->far_m[t];
    const float r_near = radius_at(near), r_far = radius_at(far);
    tile_max_[t] = std::max(r_near, r_far);
    tile_min_[t] = near <= focus && focus <= far ? radius_at(focus) : std::min(r_near, r_far);
  }
}

// The largest disc reaching each tile; returns the largest disc of all.
float DepthOfFieldLevel::spread_reach() {
  const std::vector<float>& tile_near = ranges_->near_m;
  const std::vector<float>& tile_far = ranges_->far_m;
  reach_.assign(tile_max_.size(), 0.5f);
  float reach_max = 0.5f;
  for (int ty = 0; ty < tiles_y_; ++ty) {
    for (int tx = 0; tx < tiles_x_; ++tx) {
      const float m = tile_max_[tile(tx, ty)];
      reach_max = std::max(reach_max, m);
      const int span = static_cast<int>(std::ceil(m / kTile));
      // A disc reaches the pixels it is in front of (or level with); behind a pixel only that
      // pixel's own disc gathers. So a tile wholly behind another tile does not widen its reach
      // (the background next to a sharp object leaves the object's taps few).
      const float source_near = tile_near[tile(tx, ty)];
      for (int sy = std::max(0, ty - span); sy <= std::min(tiles_y_ - 1, ty + span); ++sy) {
        for (int sx = std::max(0, tx - span); sx <= std::min(tiles_x_ - 1, tx + span); ++sx) {
          const std::size_t target = tile(sx, sy);
          if (source_near > tile_far[target] * (1 + kSameDepth)) continue;
          reach_[target] = std::max(reach_[target], m);
        }
      }
    }
  }
  return reach_max;
}

// Flat tiles: every pixel a tap of theirs can reach is within kFlatTolerance of the others, so
// the gather could not change them beyond that. They keep their values (reach 0.5).
// One-surface tiles: every pixel a tap can reach lies within kSameDepth in depth of every other
// (a margin keeps the gather's float products on the same side), so the front and behind layers
// stay empty and the cheaper gather gives the same sums.
void DepthOfFieldLevel::mark_flat_and_one_surface_tiles() {
  const std::vector<float>& tile_near = ranges_->near_m;
  const std::vector<float>& tile_far = ranges_->far_m;
  const std::vector<float>& tile_range = ranges_->radiance;  // 3 smallest, 3 largest per tile
  one_surface_.assign(tile_max_.size(), 0);
  tbb::parallel_for(tbb::blocked_range<int>(0, tiles_y_), [&](const tbb::blocked_range<int>& r) {
    for (int ty = r.begin(); ty < r.end(); ++ty) {
      for (int tx = 0; tx < tiles_x_; ++tx) {
        const std::size_t t = tile(tx, ty);
        if (reach_[t] <= 0.5f || !active(t)) continue;
        const int span = static_cast<int>(std::ceil((reach_[t] + 1) / kTile));
        float lo[3], hi[3];
        for (int c = 0; c < 3; ++c) {
          lo[c] = tile_range[6 * t + c];
          hi[c] = tile_range[6 * t + 3 + c];
        }
        float nearest = tile_near[t], furthest = tile_far[t];
        for (int sy = std::max(0, ty - span); sy <= std::min(tiles_y_ - 1, ty + span); ++sy) {
          for (int sx = std::max(0, tx - span); sx <= std::min(tiles_x_ - 1, tx + span); ++sx) {
            const std::size_t source = tile(sx, sy);
            for (int c = 0; c < 3; ++c) {
              lo[c] = std::min(lo[c], tile_range[6 * source + c]);
              hi[c] = std::max(hi[c], tile_range[6 * source + 3 + c]);
            }
            nearest = std::min(nearest, tile_near[source]);
            furthest = std::max(furthest, tile_far[source]);
          }
        }
        const float peak = std::max({hi[0], hi[1], hi[2]});
        bool flat = peak > 0;
        for (int c = 0; c < 3; ++c) flat = flat && hi[c] - lo[c] <= kFlatTolerance * peak;
        if (flat) reach_[t] = 0.5f;
        one_surface_[t] = furthest <= nearest * (1 + 0.9f * kSameDepth);
      }
    }
  });
}

// Coarse tiles: every pixel whose disc can reach them (and they themselves) blur by
// kCoarseRadiusPx or more. Their result comes from the same gather on a half-size frame. Only
// discs under kCoarseRadiusPx spoil that, and those reach no further than the tiles next door.
// Part-coarse tiles (not coarse, but with big discs of their own: the background along an
// object's silhouette) take the half-size result for those groups of pixels that no small disc
// comes near (see gather_tile).
void DepthOfFieldLevel::mark_coarse_tiles() {
  coarse_.assign(tile_max_.size(), 0);
  part_coarse_.assign(tile_max_.size(), 0);
  if (!(in_.level < kMaxCoarseLevel && w_ >= 8 * kTile && h_ >= 8 * kTile)) return;
  constexpr int span = (kSmallDiscReachPx + kTile - 1) / kTile;
  for (int ty = 0; ty < tiles_y_; ++ty) {
    for (int tx = 0; tx < tiles_x_; ++tx) {
      const std::size_t t = tile(tx, ty);
      float smallest = tile_min_[t];
      for (int sy = std::max(0, ty - span); sy <= std::min(tiles_y_ - 1, ty + span); ++sy) {
        for (int sx = std::max(0, tx - span); sx <= std::min(tiles_x_ - 1, tx + span); ++sx) {
          smallest = std::min(smallest, tile_min_[tile(sx, sy)]);
        }
      }
      // Flat tiles are copied: cheaper than their share of the half-size frame.
      coarse_[t] = active(t) && reach_[t] > 0.5f && smallest >= kCoarseRadiusPx;
      part_coarse_[t] =
          active(t) && !coarse_[t] && reach_[t] > 0.5f && tile_max_[t] >= kCoarseRadiusPx;
      any_coarse_ = any_coarse_ || coarse_[t] || part_coarse_[t];
    }
  }
}

void depth_of_field(const LevelInput& in) {
  const double f = in.camera.focal_length_m;
  if (in.depth_m.size() != static_cast<std::size_t>(in.canvas.width) * in.canvas.height ||
      !(in.focus_distance_m > f) || !(f > 0)) {
    keep_input(in);
    return;
  }
  DepthOfFieldLevel(in).run();
}

}  // namespace dof

void apply_depth_of_field(const ir::Camera& camera, double focus_distance_m,
                          const Intrinsics& canvas, const std::vector<float>& rgb,
                          const std::vector<float>& depth_m, std::vector<float>& out,
                          const DepthOfFieldOptions& options) {
  if (options.groups_with_fewer_taps != nullptr) *options.groups_with_fewer_taps = 0;
  resize_frame_buffer(out, rgb.size());
  std::vector<float> spare = take_floats(dof::coarse_output_values(canvas.width, canvas.height, 0));
  dof::depth_of_field(
      {camera, focus_distance_m, canvas, rgb, depth_m, out, 0, nullptr, options, spare});
  recycle(std::move(spare));
}

void apply_depth_of_field_in_place(const ir::Camera& camera, double focus_distance_m,
                                   const Intrinsics& canvas, std::vector<float>& rgb,
                                   const std::vector<float>& depth_m, std::vector<float>& spare,
                                   const DepthOfFieldOptions& options) {
  if (options.groups_with_fewer_taps != nullptr) *options.groups_with_fewer_taps = 0;
  const std::size_t needed = dof::in_place_spare_values(canvas.width, canvas.height);
  if (spare.size() < needed) resize_frame_buffer(spare, needed);
  dof::depth_of_field(
      {camera, focus_distance_m, canvas, rgb, depth_m, rgb, 0, nullptr, options, spare});
}

}  // namespace rigc::dslr
