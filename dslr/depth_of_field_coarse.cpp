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

#include "dslr/depth_of_field_level.h"

namespace rigc::dslr::dof {

// The half-size frame (2x2 means of the colour, the nearest depth of the four), and the level
// below gathering it. The half-size input (a third of this level's output in size) is kept in
// this level's output buffer: nothing is written there before the level below has read it all,
// and the first shot faults in fewer fresh pages. In place, the output is the input: the caller's
// spare buffer holds it instead.
void DepthOfFieldLevel::blur_coarse_tiles_at_half_size() {
  half_.width = (w_ + 1) / 2;
  half_.height = (h_ + 1) / 2;
  half_.fx = in_.canvas.fx / 2;
  half_.fy = in_.canvas.fy / 2;
  half_.cx = in_.canvas.cx / 2;
  half_.cy = in_.canvas.cy / 2;
  const std::size_t half_pixels = static_cast<std::size_t>(half_.width) * half_.height;
  const std::span<float> levels = in_.spare.last(levels_values_);
  half_out_ = levels.first(3 * half_pixels);
  const std::span<float> half_store = in_place_ ? in_.spare.first(4 * half_pixels) : in_.out;
  // 3·w·h values hold the 4·(w/2)·(h/2) (rounded up) of the input: w and h are 8 tiles or more.
  float* half_rgb = half_store.data();
  float* half_depth = half_store.data() + 3 * half_pixels;
  tbb::parallel_for(0, half_.height, [&](int hy) { downsample_row(hy, half_rgb, half_depth); });
  const std::vector<char> half_needed = half_tiles_needed();
  depth_of_field({in_.camera,
                  in_.focus_distance_m,
                  half_,
                  {half_rgb, 3 * half_pixels},
                  {half_depth, half_pixels},
                  half_out_,
                  in_.level + 1,
                  &half_needed,
                  in_.options,
                  levels.subspan(3 * half_pixels)});
}

// Half-size row hy: per value the sum 0 + the four pixels, row by row, over 4; the nearest
// positive depth of the four.
void DepthOfFieldLevel::downsample_row(int hy, float* half_rgb, float* half_depth) const {
  const int w = w_, h = h_;
  const std::span<const float> rgb = in_.rgb, depth_m = in_.depth_m;
  // Eight half pixels at a time away from the right edge: per value, the same sums in the same
  // order as the loop below, then the 24 values picked out of the 48 positions summed.
  const float* top = &rgb[3 * static_cast<std::size_t>(2 * hy) * w];
  const float* bottom = &rgb[3 * static_cast<std::size_t>(std::min(h - 1, 2 * hy + 1)) * w];
  const float* depth_top = &depth_m[static_cast<std::size_t>(2 * hy) * w];
  const float* depth_bottom = &depth_m[static_cast<std::size_t>(std::min(h - 1, 2 * hy + 1)) * w];
  using simd::I32x8;
  constexpr I32x8 kLane = {0, 1, 2, 3, 4, 5, 6, 7};
  // Half pixel hx, channel c sums positions k = 6·hx + c and k + 3 of each row.
  static constexpr I32x8 kPick[3][3] = {
      {{0, 1, 2, 6, 7, 0, 0, 0}, {0, 0, 0, 0, 0, 0, 4, 5}},
      {{6, 0, 0, 0, 0, 0, 0, 0}, {0, 2, 3, 4, 0, 0, 0, 0}, {0, 0, 0, 0, 0, 1, 2, 6}},
      {{7, 0, 0, 0, 0, 0, 0, 0}, {0, 0, 4, 5, 6, 0, 0, 0}, {0, 0, 0, 0, 0, 2, 3, 4}}};
  const Floats zero = {}, infinity = zero + std::numeric_limits<float>::infinity();
  int hx = 0;
  for (; 6 * hx + 51 <= 3 * w; hx += kLanes) {
    const int first = 6 * hx;
    Floats summed[6];
    for (int m = 0; m < 6; ++m) {
      const int k = first + kLanes * m;
      summed[m] = (((zero + load8(top + k)) + load8(top + k + 3)) + load8(bottom + k)) +
                  load8(bottom + k + 3);
    }
    const Floats part0 =
        kLane < 5 ? simd::permute(summed[0], kPick[0][0]) : simd::permute(summed[1], kPick[0][1]);
    const Floats part1 = kLane < 1 ? simd::permute(summed[1], kPick[1][0])
                                   : (kLane < 4 ? simd::permute(summed[2], kPick[1][1])
                                                : simd::permute(summed[3], kPick[1][2]));
    const Floats part2 = kLane < 1 ? simd::permute(summed[3], kPick[2][0])
                                   : (kLane < 5 ? simd::permute(summed[4], kPick[2][1])
                                                : simd::permute(summed[5], kPick[2][2]));
    float* out_rgb = &half_rgb[3 * (static_cast<std::size_t>(hy) * half_.width + hx)];
    const Floats values[3] = {part0 / 4, part1 / 4, part2 / 4};
    std::memcpy(out_rgb, values, sizeof values);
    // Depth: the nearest positive of the four (min does not depend on the order).
    constexpr I32x8 kEven = {0, 2, 4, 6, 0, 2, 4, 6}, kOdd = {1, 3, 5, 7, 1, 3, 5, 7};
    Floats nearest = infinity;
    for (const float* row : {depth_top, depth_bottom}) {
      const Floats left = load8(row + 2 * hx), right = load8(row + 2 * hx + kLanes);
      const Floats even = kLane < 4 ? simd::permute(left, kEven) : simd::permute(right, kEven);
      const Floats odd = kLane < 4 ? simd::permute(left, kOdd) : simd::permute(right, kOdd);
      for (const Floats& d : {even, odd}) {
        const Floats positive = d > zero ? d : infinity;
        nearest = positive < nearest ? positive : nearest;
      }
    }
    std::memcpy(&half_depth[static_cast<std::size_t>(hy) * half_.width + hx], &nearest,
                sizeof nearest);
  }
  for (; hx < half_.width; ++hx) {
    float sum[3] = {0, 0, 0}, nearest = std::numeric_limits<float>::infinity();
    for (int dy = 0; dy < 2; ++dy) {
      for (int dx = 0; dx < 2; ++dx) {
        const std::size_t p = static_cast<std::size_t>(std::min(h - 1, 2 * hy + dy)) * w +
                              std::min(w - 1, 2 * hx + dx);
        for (int c = 0; c < 3; ++c) sum[c] += rgb[3 * p + c];
        if (depth_m[p] > 0) nearest = std::min(nearest, depth_m[p]);
      }
    }
    const std::size_t q = static_cast<std::size_t>(hy) * half_.width + hx;
    for (int c = 0; c < 3; ++c) half_rgb[3 * q + c] = sum[c] / 4;
    half_depth[q] = nearest;
  }
}

// The tiles of the level below that the coarse tiles here sample (bilinear: with a margin of one
// tile).
std::vector<char> DepthOfFieldLevel::half_tiles_needed() const {
  const int half_tiles_x = (half_.width + kTile - 1) / kTile;
  const int half_tiles_y = (half_.height + kTile - 1) / kTile;
  std::vector<char> half_needed(static_cast<std::size_t>(half_tiles_x) * half_tiles_y, 0);
  for (int ty = 0; ty < tiles_y_; ++ty) {
    for (int tx = 0; tx < tiles_x_; ++tx) {
      const std::size_t t = tile(tx, ty);
      if (!coarse_[t] && !part_coarse_[t]) continue;
      for (int hy = std::max(0, (ty - 1) / 2); hy <= std::min(half_tiles_y - 1, (ty + 1) / 2);
           ++hy) {
        for (int hx = std::max(0, (tx - 1) / 2); hx <= std::min(half_tiles_x - 1, (tx + 1) / 2);
             ++hx) {
          half_needed[static_cast<std::size_t>(hy) * half_tiles_x + hx] = 1;
        }
      }
    }
  }
  return half_needed;
}

// The half-size row above full row y's centre, and its weight against the row below.
int DepthOfFieldLevel::half_row_of(int y, float* weight) const {
  const float hy = std::clamp((y + 0.5f) / 2 - 0.5f, 0.0f, half_.height - 1.0f);
  const int iy = std::min(static_cast<int>(hy), half_.height - 2);
  *weight = hy - iy;
  return iy;
}

// Bilinear from the half-size result: full pixel centre x + 0.5 sits at half x (x + 0.5) / 2.
void DepthOfFieldLevel::upsample_tile(int x0, int x1, int y0, int y1) const {
  // Each column's two half-size neighbours and weight, the same on every row of the tile.
  std::array<int, kTile> column;
  std::array<float, kTile> column_weight;
  for (int x = x0; x < x1; ++x) {
    const float hx = std::clamp((x + 0.5f) / 2 - 0.5f, 0.0f, half_.width - 1.0f);
    column[x - x0] = std::min(static_cast<int>(hx), half_.width - 2);
    column_weight[x - x0] = hx - column[x - x0];
  }
  const int first = column[0], count = column[x1 - 1 - x0] + 2 - first;
  // A whole tile away from the frame's edges: its columns follow the fixed pattern of
  // upsample_interior_tile.
  const bool interior = x1 - x0 == kTile && x0 >= 2 && first == x0 / 2 - 1 &&
                        column[kTile - 1] == x0 / 2 + kTile / 2 - 1 && count == kTile / 2 + 2;
  if (interior) {
    upsample_interior_tile(x0, y0, y1, first);
    return;
  }
  std::array<float, 3 * (kTile / 2 + 3)> blended;  // this row's vertical blend, from `first`
  for (int y = y0; y < y1; ++y) {
    float fy;
    const int iy = half_row_of(y, &fy);
    const float* a = &half_out_[3 * (static_cast<std::size_t>(iy) * half_.width + first)];
    const float* b = a + 3 * static_cast<std::size_t>(half_.width);
    for (int k = 0; k < 3 * count; ++k) blended[k] = a[k] + fy * (b[k] - a[k]);
    float* dst = &in_.out[3 * (static_cast<std::size_t>(y) * w_ + x0)];
    for (int x = 0; x < x1 - x0; ++x) {
      const float* v = &blended[3 * (column[x] - first)];
      const float fx = column_weight[x];
      for (int c = 0; c < 3; ++c) dst[3 * x + c] = v[c] + fx * (v[3 + c] - v[c]);
    }
  }
}

// Across first: the half rows this tile reads (ten), each spread to the tile's width (pixel
// x0 + 2k sits a quarter of a half pixel left of half pixel x0/2 + k, pixel x0 + 2k + 1 a quarter
// right: fixed weights), then each row blends two of them. All loops run over contiguous values.
void DepthOfFieldLevel::upsample_interior_tile(int x0, int y0, int y1, int first) const {
  constexpr int kValues = 3 * kTile;
  float unused;
  const int row_first = half_row_of(y0, &unused), row_last = half_row_of(y1 - 1, &unused) + 1;
  // One value of padding: each pixel is stored as four lanes, the fourth overwritten next.
  std::array<float, kValues*(kTile / 2 + 2) + 1> spread;
  using simd::F32x4;
  using simd::load4;
  for (int j = row_first; j <= row_last; ++j) {
    const float* v = &half_out_[3 * (static_cast<std::size_t>(j) * half_.width + first)];
    float* row = &spread[(j - row_first) * kValues];
    F32x4 here = load4(v);
    for (int k = 0; k < kTile / 2; ++k) {
      const F32x4 next = load4(v + 3 * k + 3);
      // The last pixel's fourth lane would read past the tile's half pixels: read up to them.
      F32x4 after;
      if (k + 1 < kTile / 2) {
        after = load4(v + 3 * k + 6);
      } else {
        after = F32x4{v[3 * k + 6], v[3 * k + 7], v[3 * k + 8], 0.0f};
      }
      const F32x4 left = 0.25f * here + 0.75f * next;
      const F32x4 right = 0.75f * next + 0.25f * after;
      std::memcpy(row + 6 * k, &left, sizeof left);
      std::memcpy(row + 6 * k + 3, &right, sizeof right);
      here = next;
    }
  }
  for (int y = y0; y < y1; ++y) {
    float fy;
    const int iy = half_row_of(y, &fy);
    const float* a = &spread[(iy - row_first) * kValues];
    const float* b = a + kValues;
    float* dst = &in_.out[3 * (static_cast<std::size_t>(y) * w_ + x0)];
    for (int k = 0; k < kValues; ++k) dst[k] = a[k] + fy * (b[k] - a[k]);
  }
}

// Coarse tiles come from the half-size result.
void DepthOfFieldLevel::upsample_coarse_tiles(const StripRows& rows) const {
  for (int ty = rows.ty0; ty < rows.ty1; ++ty) {
    for (int tx = 0; tx < tiles_x_; ++tx) {
      const std::size_t t = tile(tx, ty);
      if (!active(t) || !coarse_[t]) continue;
      upsample_tile(tx * kTile, std::min(w_, (tx + 1) * kTile), ty * kTile,
                    std::min(h_, (ty + 1) * kTile));
    }
  }
}

}  // namespace rigc::dslr::dof
