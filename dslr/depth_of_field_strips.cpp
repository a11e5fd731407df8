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

namespace rigc::dslr::dof {
namespace {

inline Floats clamp01(Floats v) {
  const Floats zero = {}, one = zero + 1;
  v = v < zero ? zero : v;
  return v > one ? one : v;
}

// Taps [begin, end) on the pixels' own surface: each tap's disc weight and colour into the same
// layer's sums (inlined into each gather, so the sums stay in registers).
[[gnu::always_inline]] inline void one_surface_taps(const Planes& pl, const TapSet& set, int begin,
                                                    int end, std::size_t i, Floats& ws_sum,
                                                    Floats& sr, Floats& sg, Floats& sb) {
  for (int t = begin; t < end; ++t) {
    const std::ptrdiff_t q = static_cast<std::ptrdiff_t>(i) + set.dy[t] * pl.stride + set.dx[t];
    const float d = set.distance[t], area = set.area[t], inv_soft = set.inv_soft[t];
    const Floats rq = load8(&pl.radius[q]);
    const Floats ws = area * clamp01((rq - d) * inv_soft + 0.5f) * load8(&pl.inv_area[q]);
    const Floats r = load8(&pl.r[q]), g = load8(&pl.g[q]), b = load8(&pl.b[q]);
    ws_sum += ws;
    sr += ws * r, sg += ws * g, sb += ws * b;
  }
}

// One row of kLanes neighbouring pixels against taps [0, tap_count): the loads for a tap are
// contiguous, so this vectorises. AVX2 where the CPU has it, SSE otherwise.
// Taps [three_layer, tap_count) are known to hold no pixel behind any of the eight and no pixel
// in front of one whose disc reaches that far: there the front and behind terms add exact zeros,
// so they take the one-surface arithmetic (the same sums, in the same order).
__attribute__((target_clones("avx2", "default"))) void gather_group(const Planes& pl,
                                                                    const TapSet& set,
                                                                    int tap_count, std::size_t i,
                                                                    GroupSums& s, int three_layer) {
  const Floats zp = load8(&pl.z[i]), rp = load8(&pl.radius[i]);
  const Floats z_front = zp * (1 - kSameDepth), z_back = zp * (1 + kSameDepth);
  const Floats zero = {};
  // Locals rather than s's members, so the accumulators can stay in registers.
  Floats wf_sum = zero, ws_sum = zero, wb_sum = zero;
  Floats fr = zero, fg = zero, fb = zero, sr = zero, sg = zero, sb = zero, br = zero, bg = zero,
         bb = zero;
  const int layered = std::min(three_layer, tap_count);
  for (int t = 0; t < layered; ++t) {
    const std::ptrdiff_t q = static_cast<std::ptrdiff_t>(i) + set.dy[t] * pl.stride + set.dx[t];
    const float d = set.distance[t], area = set.area[t], inv_soft = set.inv_soft[t];
    const Floats zq = load8(&pl.z[q]), rq = load8(&pl.radius[q]);
    // In front or on the same surface: q's own disc must reach p, with q's energy per pixel.
    const Floats w_disc = area * clamp01((rq - d) * inv_soft + 0.5f) * load8(&pl.inv_area[q]);
    // Behind: seen only through p's own disc, so a sharp p never picks it up.
    const Floats w_behind = area * clamp01((rp - d) * inv_soft + 0.5f);
    const auto front = zq < z_front;
    const auto behind = zq > z_back;
    const Floats wf = front ? w_disc : zero;
    const Floats wb = behind ? w_behind : zero;
    const Floats ws = (front | behind) ? zero : w_disc;
    const Floats r = load8(&pl.r[q]), g = load8(&pl.g[q]), b = load8(&pl.b[q]);
    wf_sum += wf, ws_sum += ws, wb_sum += wb;
    fr += wf * r, fg += wf * g, fb += wf * b;
    sr += ws * r, sg += ws * g, sb += ws * b;
    br += wb * r, bg += wb * g, bb += wb * b;
  }
  one_surface_taps(pl, set, layered, tap_count, i, ws_sum, sr, sg, sb);
  s.wf = wf_sum, s.ws = ws_sum, s.wb = wb_sum;
  s.front[0] = fr, s.front[1] = fg, s.front[2] = fb;
  s.same[0] = sr, s.same[1] = sg, s.same[2] = sb;
  s.behind[0] = br, s.behind[1] = bg, s.behind[2] = bb;
}

// gather_group where every tap lies on the pixels' own surface (depths within kSameDepth of
// theirs): the same sums, without the front and behind layers, which stay zero.
__attribute__((target_clones("avx2", "default"))) void gather_group_one_surface(
    const Planes& pl, const TapSet& set, int tap_count, std::size_t i, GroupSums& s, int) {
  const Floats zero = {};
  Floats ws_sum = zero, sr = zero, sg = zero, sb = zero;
  one_surface_taps(pl, set, 0, tap_count, i, ws_sum, sr, sg, sb);
  s.wf = zero, s.ws = ws_sum, s.wb = zero;
  for (int k = 0; k < 3; ++k) s.front[k] = s.behind[k] = zero;
  s.same[0] = sr, s.same[1] = sg, s.same[2] = sb;
}

// Front-to-back compositing of the three layers, for the group's first `count` pixels: all
// lanes at once, then stored interleaved. (ws > 0 always: a pixel's own tap covers it.)
void composite(const GroupSums& s, int count, float* out) {
  const Floats zero = {}, one = zero + 1;
  const auto has_behind = s.wb > zero, has_front = s.wf > zero;
  const Floats alpha_same = has_behind ? (s.ws < one ? s.ws : one) : one;
  const Floats alpha_front = s.wf < one ? s.wf : one;
  // Lanes without a layer divide by zero here; the selects below drop them.
  const Floats inv_ws = one / s.ws, inv_wb = one / s.wb, inv_wf = one / s.wf;
  Floats v[3];
  for (int k = 0; k < 3; ++k) {
    v[k] = alpha_same * s.same[k] * inv_ws;
    v[k] = has_behind ? v[k] + (1 - alpha_same) * s.behind[k] * inv_wb : v[k];
    v[k] = has_front ? alpha_front * s.front[k] * inv_wf + (1 - alpha_front) * v[k] : v[k];
  }
  for (int lane = 0; lane < count; ++lane) {
    for (int k = 0; k < 3; ++k) out[3 * lane + k] = v[k][lane];
  }
}

// The taps a group of pixels gathers: all `count` of them, the first `three_layer` in three layers.
struct GroupTaps {
  int three_layer, count;
};

// A strip is filled and gathered in blocks of this many columns: a block's planes are still in the
// core's cache when its tiles gather from them, and the next block but one fills the same memory
// again.
constexpr int kBlockColumns = 256;
static_assert(kBlockColumns % kTile == 0);

// Each thread's planes for two blocks of a strip's columns, kept between frames.
std::array<Planes, 2>& thread_block_planes() {
  thread_local std::array<Planes, 2> planes;
  return planes;
}

// Padding (outside the image) holds no energy and sits in front of everything.
void clear_planes(Planes& pl, std::size_t begin, std::size_t end) {
  for (auto* plane : {&pl.r, &pl.g, &pl.b, &pl.inv_area}) {
    std::fill(plane->begin() + begin, plane->begin() + end, 0.0f);
  }
  std::fill(pl.z.begin() + begin, pl.z.begin() + end, -std::numeric_limits<float>::infinity());
  std::fill(pl.radius.begin() + begin, pl.radius.begin() + end, 0.5f);
}

// The taps the group of eight pixels at (x, y) needs, of a tile's `tap_count`. A tap at distance d
// weighs nothing unless the disc it tests reaches d: the disc of the pixel q there when q is in
// front of or level with the group's pixel, the pixel's own when q is behind. So beyond the
// largest of the group's own discs and the discs of every q within the tile's taps (`extent`)
// that is not behind the group's furthest pixel, the remaining taps add exact zeros. Along a
// silhouette that spares the object's pixels the background's big discs, which lie behind them.
// Also the taps from which no pixel is behind any of the group's (behind its nearest) and no disc
// of a pixel in front of one of them (of its furthest) reaches: from there on the cheaper
// arithmetic of one surface gives the same sums. Counts the groups that need fewer taps.
// (Seven parameters: one group's place in the planes, inlined into the gather.)
GroupTaps taps_for_group(const Planes& pl, const TapSet& set, int x, int y, int tap_count,
                         int extent, std::int64_t& groups_with_fewer_taps) {
  const std::size_t i = pl.index(x, y);
  const Floats zp = load8(&pl.z[i]);
  float z_furthest = zp[0], z_nearest = zp[0];
  for (int k = 1; k < kLanes; ++k) {
    z_furthest = std::max(z_furthest, zp[k]);
    z_nearest = std::min(z_nearest, zp[k]);
  }
  const float z_behind = z_furthest * (1 + kSameDepth);
  // As gather_group compares: behind the nearest pixel, in front of the furthest.
  const float z_behind_nearest = z_nearest * (1 + kSameDepth);
  const float z_front_furthest = z_furthest * (1 - kSameDepth);
  Floats front_largest = {};
  simd::I32x8 any_behind = {};
  // The window's columns in whole registers, the last one overlapping the one before (columns
  // counted twice change no maximum).
  const int columns = kLanes + 2 * extent;
  Floats largest = {};
  for (int dy = -extent; dy <= extent; ++dy) {
    const std::size_t row = pl.index(x - extent, y + dy);
    for (int dx = 0; dx < columns; dx += kLanes) {
      const std::size_t q = row + std::min(dx, columns - kLanes);
      const Floats zq = load8(&pl.z[q]), rq = load8(&pl.radius[q]);
      const Floats counted = zq > z_behind ? Floats{} : rq;
      largest = largest > counted ? largest : counted;
      const Floats front = zq < z_front_furthest ? rq : Floats{};
      front_largest = front_largest > front ? front_largest : front;
      any_behind |= zq > z_behind_nearest;
    }
  }
  // The group's own pixels lie in the window and are never behind the furthest of them: their
  // discs are in `largest`.
  float needed = 0, front_needed = 0;
  for (int k = 0; k < kLanes; ++k) {
    needed = std::max(needed, largest[k]);
    front_needed = std::max(front_needed, front_largest[k]);
  }
  const int taps = std::min(tap_count, set.taps_for(needed));
  groups_with_fewer_taps += taps < tap_count;
  if (simd::any(any_behind)) return {taps, taps};
  return {std::min(taps, set.taps_for(front_needed)), taps};
}

}  // namespace

// The padding the tiles gathered at this level need (the big discs of coarse tiles are gathered
// below), the strips' height, and each strip's plan.
void DepthOfFieldLevel::plan_strips() {
  float fine_reach_max = 0.5f;
  for (std::size_t t = 0; t < reach_.size(); ++t) {
    if (active(t) && !coarse_[t]) fine_reach_max = std::max(fine_reach_max, reach_[t]);
  }
  const int max_taps = set_.taps_for(fine_reach_max);
  int tap_extent = 0;
  for (int t = 0; t < max_taps; ++t) {
    tap_extent = std::max({tap_extent, std::abs(set_.dx[t]), std::abs(set_.dy[t])});
  }
  pad_ = tap_extent + 1;
  strip_rows_ = std::max(2 * kTile, (4 * pad_ + kTile - 1) / kTile * kTile);
  strips_ = (h_ + strip_rows_ - 1) / strip_rows_;
  plans_.assign(static_cast<std::size_t>(strips_), StripPlan{});
  for (int strip = 0; strip < strips_; ++strip) {
    StripPlan& plan = plans_[static_cast<std::size_t>(strip)];
    const StripRows rows = rows_of(strip);
    plan.span_x0 = w_;
    for (int ty = rows.ty0; ty < rows.ty1; ++ty) {
      for (int tx = 0; tx < tiles_x_; ++tx) {
        const std::size_t t = tile(tx, ty);
        if (!active(t) || coarse_[t]) continue;
        plan.reach = std::max(plan.reach, reach_[t]);
        if (reach_[t] <= 0.5f) continue;
        plan.span_x0 = std::min(plan.span_x0, tx * kTile);
        plan.span_x1 = std::max(plan.span_x1, (tx + 1) * kTile);
      }
    }
  }
}

StripRows DepthOfFieldLevel::rows_of(int strip) const {
  const int y0 = strip * strip_rows_, y1 = std::min(h_, y0 + strip_rows_);
  return {y0, y1, y0 / kTile, (y1 + kTile - 1) / kTile};
}

// The rows next to each border between strips (see Halo), kept where the half-size input was
// (the levels below have read it by now), in `spare` before the levels' outputs; when they need
// more, in a buffer the calling thread keeps between frames.
void DepthOfFieldLevel::keep_halos() {
  thread_local std::vector<float> kept_halo_values;
  halos_.assign(static_cast<std::size_t>(strips_), Halo{});
  std::size_t total = 0;
  for (int strip = 1; strip < strips_; ++strip) {
    const StripPlan &above = plans_[static_cast<std::size_t>(strip) - 1],
                    &below = plans_[static_cast<std::size_t>(strip)];
    if (!above.fills() && !below.fills()) continue;
    Halo& halo = halos_[static_cast<std::size_t>(strip)];
    const int border = strip * strip_rows_;
    halo.first_row = std::max(0, border - pad_);
    halo.rows = std::min(h_, border + pad_) - halo.first_row;
    halo.x0 = w_;
    for (const StripPlan* plan : {&above, &below}) {
      if (!plan->fills()) continue;
      halo.x0 = std::min(halo.x0, std::max(0, plan->span_x0 - pad_));
      halo.x1 = std::max(halo.x1, std::min(w_, plan->span_x1 + pad_));
    }
    halo.offset = total;
    total += 3 * static_cast<std::size_t>(halo.rows) * std::max(0, halo.x1 - halo.x0);
  }
  if (total <= in_.spare.size() - levels_values_) {
    halo_values_ = in_.spare.data();
  } else {
    if (kept_halo_values.size() < total) resize_frame_buffer(kept_halo_values, total);
    halo_values_ = kept_halo_values.data();
  }
  tbb::parallel_for(1, std::max(1, strips_), [&](int strip) {
    const Halo& halo = halos_[static_cast<std::size_t>(strip)];
    const std::size_t row_values = 3 * static_cast<std::size_t>(std::max(0, halo.x1 - halo.x0));
    for (int k = 0; k < halo.rows; ++k) {
      const float* from =
          &in_.rgb[3 * (static_cast<std::size_t>(halo.first_row + k) * w_ + halo.x0)];
      std::copy(from, from + row_values, &halo_values_[halo.offset + k * row_values]);
    }
  });
}

// Where row y of the input is to be read, for strip `strip` (its own rows from the frame, the
// others from the halos), as a pointer to the row's pixel x = 0 minus `column_base` pixels.
const float* DepthOfFieldLevel::input_row(int strip, int y, int* column_base) const {
  const int sy0 = strip * strip_rows_, sy1 = std::min(h_, sy0 + strip_rows_);
  if (!in_place_ || (y >= sy0 && y < sy1)) {
    *column_base = 0;
    return &in_.rgb[3 * static_cast<std::size_t>(y) * w_];
  }
  const Halo& halo = halos_[static_cast<std::size_t>(y < sy0 ? strip : strip + 1)];
  *column_base = halo.x0;
  return &halo_values_[halo.offset + 3 * static_cast<std::size_t>(y - halo.first_row) *
                                         static_cast<std::size_t>(halo.x1 - halo.x0)];
}

void DepthOfFieldLevel::blur_strips() {
  std::atomic<std::int64_t> groups_with_fewer_taps{0};
  tbb::parallel_for(tbb::blocked_range<int>(0, strips_, 1), [&](const tbb::blocked_range<int>& r) {
    std::array<Planes, 2>& block_planes = thread_block_planes();
    GroupSums sums;
    std::int64_t strip_groups_with_fewer_taps = 0;
    for (int strip = r.begin(); strip < r.end(); ++strip) {
      blur_strip(strip, block_planes, sums, strip_groups_with_fewer_taps);
    }
    groups_with_fewer_taps.fetch_add(strip_groups_with_fewer_taps, std::memory_order_relaxed);
  });
  if (in_.options.groups_with_fewer_taps != nullptr) {
    *in_.options.groups_with_fewer_taps += groups_with_fewer_taps.load();
  }
}

// A strip's blocks of columns, each filled into planes and gathered; then its coarse tiles (in
// place, only once every block of the strip has its rows in its planes: coarse tiles within a
// block's padding were read as they were) and its sharp ones.
void DepthOfFieldLevel::blur_strip(int strip, std::array<Planes, 2>& block_planes, GroupSums& sums,
                                   std::int64_t& groups_with_fewer_taps) const {
  const StripRows rows = rows_of(strip);
  const StripPlan& plan = plans_[static_cast<std::size_t>(strip)];
  if (plan.fills()) {                  // otherwise sharp, apart from any coarse tiles
    const Planes* previous = nullptr;  // the block to the left, as it was filled
    int parity = 0;
    for (int bx0 = plan.span_x0; bx0 < plan.span_x1; bx0 += kBlockColumns, parity ^= 1) {
      const int bx1 = std::min(plan.span_x1, bx0 + kBlockColumns);
      Planes& pl = block_planes[parity];
      fill_block(pl, previous, strip, rows, bx0, bx1);
      previous = &pl;
      for (int ty = rows.ty0; ty < rows.ty1; ++ty) {
        for (int tx = bx0 / kTile; tx < (bx1 + kTile - 1) / kTile; ++tx) {
          gather_tile(pl, tx, ty, sums, groups_with_fewer_taps);
        }
      }
    }
  }
  upsample_coarse_tiles(rows);
  copy_sharp_tiles(rows);
}

// Tiles where everything, around them too, is sharp keep their values: in place they are not
// touched, and a copy takes them as they are.
void DepthOfFieldLevel::copy_sharp_tiles(const StripRows& rows) const {
  if (in_place_) return;
  for (int ty = rows.ty0; ty < rows.ty1; ++ty) {
    for (int tx = 0; tx < tiles_x_; ++tx) {
      const std::size_t t = tile(tx, ty);
      if (coarse_[t] || !active(t) || reach_[t] > 0.5f) continue;
      const int x0 = tx * kTile, x1 = std::min(w_, x0 + kTile);
      for (int y = ty * kTile; y < std::min(h_, (ty + 1) * kTile); ++y) {
        const std::size_t a = 3 * (static_cast<std::size_t>(y) * w_ + x0);
        std::copy(in_.rgb.begin() + a, in_.rgb.begin() + a + 3 * (x1 - x0), in_.out.begin() + a);
      }
    }
  }
}

// The planes of columns [bx0, bx1) of a strip, with the padding its taps read.
void DepthOfFieldLevel::fill_block(Planes& pl, const Planes* previous, int strip,
                                   const StripRows& rows, int bx0, int bx1) const {
  const int pad = pad_, w = w_, h = h_;
  const int plane_rows = rows.y1 - rows.y0 + 2 * pad;
  pl.pad = pad;
  pl.x0 = bx0;
  pl.y0 = rows.y0;
  pl.stride = bx1 - bx0 + 2 * pad;
  const std::size_t size = static_cast<std::size_t>(pl.stride) * plane_rows;
  // A plain resize (under 1 MB a plane, even for the widest padding): the frame buffers' first
  // touch runs a nested parallel loop, during which this thread could take up another strip with
  // these same thread_local planes.
  for (auto* plane : {&pl.r, &pl.g, &pl.b, &pl.z, &pl.radius, &pl.inv_area}) {
    if (plane->size() < size) plane->resize(size);
  }
  // Only the columns the block's taps read: its tiles' columns widened by the padding (a partial
  // last tile's last group reads on to the tile's edge, inside the span).
  const int fill_x0 = std::max(-pad, bx0 - pad);
  const int fill_x1 = std::min(w + pad + kTile, bx1 + pad);
  // The block to the left has written its tiles by now (in place, into the frame): the columns of
  // its that this block's taps read come from its planes, as they were filled. (So in both modes;
  // the copying mode's test cannot tell them apart.)
  const int copied_x1 = previous != nullptr ? bx0 : fill_x0;
  for (int y = rows.y0 - pad; y < rows.y1 + pad; ++y) {
    const std::size_t row_begin = pl.index(fill_x0, y);  // x = fill_x0 of this row
    // Plane positions of x, for x from fill_x0 on.
    auto at = [&](int x) { return row_begin + static_cast<std::size_t>(x - fill_x0); };
    if (y < 0 || y >= h) {
      clear_planes(pl, at(fill_x0), at(fill_x1));
      continue;
    }
    if (copied_x1 > fill_x0) {
      const std::size_t from = previous->index(fill_x0, y);
      const auto count = static_cast<std::size_t>(copied_x1 - fill_x0);
      for (auto plane :
           {&Planes::r, &Planes::g, &Planes::b, &Planes::z, &Planes::radius, &Planes::inv_area}) {
        std::copy_n((previous->*plane).begin() + from, count, (pl.*plane).begin() + at(fill_x0));
      }
    }
    if (copied_x1 < 0) clear_planes(pl, at(copied_x1), at(0));
    if (fill_x1 > w) clear_planes(pl, at(std::max(w, copied_x1)), at(fill_x1));
    fill_row(pl, strip, y, fill_x0, std::max(0, copied_x1), std::min(w, fill_x1));
  }
}

// Image columns [fill_begin, fill_end) of row y into the planes, whose row begins at fill_x0.
void DepthOfFieldLevel::fill_row(Planes& pl, int strip, int y, int fill_x0, int fill_begin,
                                 int fill_end) const {
  const BlurRadius radius_at = radius_at_;
  const float inf = std::numeric_limits<float>::infinity();
  const std::size_t at_begin =
      pl.index(fill_x0, y) + static_cast<std::size_t>(fill_begin - fill_x0);
  const std::size_t image_row = static_cast<std::size_t>(y) * w_;
  // Pointers at x = fill_begin.
  float* r = &pl.r[at_begin];
  float* g = &pl.g[at_begin];
  float* b = &pl.b[at_begin];
  float* zs = &pl.z[at_begin];
  float* radii = &pl.radius[at_begin];
  float* inv_area = &pl.inv_area[at_begin];
  // Depth-derived planes and the colour planes in two loops: each reads one contiguous input, so
  // both vectorise.
  const float* depth_row = &in_.depth_m[image_row + fill_begin];
  const int count = std::max(0, fill_end - fill_begin);
  // Eight at a time (the compiler leaves the plain loop scalar), then the rest.
  int x = 0;
  {
    const Floats zero = {}, infinity = zero + inf;
    for (; x + kLanes <= count; x += kLanes) {
      const Floats depth = load8(depth_row + x);
      const Floats z = depth > zero ? depth : infinity;
      const Floats radius = radius_at(z);
      const Floats area = 1 / (std::numbers::pi_v<float> * radius * radius);
      std::memcpy(zs + x, &z, sizeof z);
      std::memcpy(radii + x, &radius, sizeof radius);
      std::memcpy(inv_area + x, &area, sizeof area);
    }
  }
  for (; x < count; ++x) {
    const float z = depth_row[x] > 0 ? depth_row[x] : inf;
    const float radius = radius_at(z);
    zs[x] = z;
    radii[x] = radius;
    inv_area[x] = 1 / (std::numbers::pi_v<float> * radius * radius);
  }
  int column_base = 0;
  const float* colour_row =
      input_row(strip, y, &column_base) + 3 * static_cast<std::ptrdiff_t>(fill_begin);
  for (int x = 0; x < count; ++x) {
    r[x] = colour_row[3 * (x - column_base)];
    g[x] = colour_row[3 * (x - column_base) + 1];
    b[x] = colour_row[3 * (x - column_base) + 2];
  }
}

// Tile (tx, ty) from the block's planes, group of eight pixels by group.
void DepthOfFieldLevel::gather_tile(const Planes& pl, int tx, int ty, GroupSums& sums,
                                    std::int64_t& groups_with_fewer_taps) const {
  const int x0 = tx * kTile, x1 = std::min(w_, x0 + kTile);
  const int y0 = ty * kTile, y1 = std::min(h_, y0 + kTile);
  const std::size_t t = tile(tx, ty);
  if (coarse_[t] || !active(t)) return;  // upsampled, or not asked for
  const float radius = reach_[t];
  if (radius <= 0.5f) return;  // copy_sharp_tiles
  const TapSet& set = set_;
  const int tap_count = set.taps_for(radius);
  // Every pixel a tap can reach on one surface: the cheaper gather, same sums.
  const auto gather = one_surface_[t] ? gather_group_one_surface : gather_group;
  // Narrowed per group (taps_for_group) only for the three-layer gather: one surface has no
  // "behind".
  const int extent = set.extent_of_count[tap_count];
  const bool per_group =
      in_.options.taps_per_group && !one_surface_[t] && tap_count > set.taps_for(2.0f);
  // Part-coarse tiles: a group of pixels whose discs, and all discs within kSmallDiscReachPx of
  // it, have kCoarseRadiusPx or more is upsampled like a coarse tile. The smallest disc over each
  // row's window, per group, then over the rows.
  constexpr int d = kSmallDiscReachPx;
  constexpr int kGroups = kTile / kLanes;
  const bool split = part_coarse_[t] && pl.pad >= d;
  std::array<float, (kTile + 2 * d) * kGroups> row_smallest;
  if (split) {
    for (int y = y0 - d; y < y1 + d; ++y) {
      const float* radii = &pl.radius[pl.index(x0 - d, y)];  // from x0 - d
      for (int g = 0; g < kGroups; ++g) {
        const int gx = g * kLanes;  // from x0
        float smallest = radii[gx];
        for (int x = gx + 1; x < gx + kLanes + 2 * d; ++x) smallest = std::min(smallest, radii[x]);
        row_smallest[(y - y0 + d) * kGroups + g] = smallest;
      }
    }
  }
  for (int y = y0; y < y1; ++y) {
    for (int x = x0; x < x1; x += kLanes) {
      if (split) {
        const int g = (x - x0) / kLanes;
        float smallest = row_smallest[(y - y0) * kGroups + g];
        for (int k = 1; k <= 2 * d; ++k) {
          smallest = std::min(smallest, row_smallest[(y - y0 + k) * kGroups + g]);
        }
        if (smallest >= kCoarseRadiusPx) {
          upsample_tile(x, std::min(x + kLanes, x1), y, y + 1);
          continue;
        }
      }
      const GroupTaps taps =
          per_group ? taps_for_group(pl, set, x, y, tap_count, extent, groups_with_fewer_taps)
                    : GroupTaps{tap_count, tap_count};
      gather(pl, set, taps.count, pl.index(x, y), sums, taps.three_layer);
      composite(sums, std::min(kLanes, x1 - x),
                &in_.out[3 * (static_cast<std::size_t>(y) * w_ + x)]);
    }
  }
}

}  // namespace rigc::dslr::dof
