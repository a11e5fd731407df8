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
#include "dslr/optics.h"
#include "dslr/simd.h"

// The 32-byte vectors of the gather are only passed between functions inlined into the AVX2 and
// the default clone of one function, so GCC's note on their ABI without AVX does not apply.
#pragma GCC diagnostic ignored "-Wpsabi"

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

namespace {

constexpr int kTile = 16;            // pixels per side of a tile that shares one tap count
constexpr int kLanes = 8;            // pixels gathered together (one AVX register)
constexpr float kSameDepth = 0.02f;  // relative depth band counted as "the same surface"
constexpr double kDenseRadius = 4.5, kRingRatio = 1.3;
// Where every disc that can reach a tile has at least this radius, the tile is gathered at half
// resolution and upsampled (the blur this adds is taken out of the discs, see BlurRadius), and
// the gather costs a sixteenth (a quarter of the pixels, a quarter of the taps each). At full
// resolution, out-of-focus backgrounds are most of the frame. 4 px keeps the thin-lens edge
// widths within the tests' 15 %; a smaller radius costs more, a larger one widens the edges.
constexpr float kCoarseRadiusPx = 4.0f;
// How far from a pixel a disc smaller than kCoarseRadiusPx can change its half-resolution value:
// the disc itself, plus the bilinear upsampling's half pixels and their 2 x 2 footprints.
constexpr int kSmallDiscReachPx = static_cast<int>(kCoarseRadiusPx) + 3;
// A tile whose every reachable pixel lies within this fraction of the brightest value there (per
// channel) is copied instead of gathered: any blur of it is a weighted mean of those pixels, so it
// moves by less than this. Smooth backdrops (a green screen) are most of a frame's big discs;
// 0.4 % is under the sensor's shot noise at any ISO and under one 8-bit sRGB code in light tones.
constexpr float kFlatTolerance = 0.004f;

struct TapSet {
  // Sorted by distance; structure of arrays for the gather loop.
  std::vector<int> dx, dy;
  std::vector<float> distance;
  std::vector<float> area;      // pixels this tap stands for
  std::vector<float> inv_soft;  // 1 / width of the coverage ramp at the disc edge
  // For a radius of q/4 pixels: how many leading taps a disc that large can cover (the rest
  // weigh nothing). Quarter steps: a disc of 1.1 px needs 9 taps, not the 21 of a 2 px one.
  std::vector<int> count_for_quarter;
  // extent_of_count[k]: how far (in x or y) the first k taps reach.
  std::vector<int> extent_of_count;
  int taps_for(float radius) const {
    const int q = std::min(static_cast<int>(std::ceil(radius * 4)),
                           static_cast<int>(count_for_quarter.size()) - 1);
    return count_for_quarter[std::max(q, 0)];
  }
};

const TapSet& tap_set() {
  static const TapSet set = [] {
    struct Tap {
      int dx, dy;
      float distance, area, inv_soft;
    };
    std::vector<Tap> taps;
    const int d = static_cast<int>(kDenseRadius);
    for (int dy = -d; dy <= d; ++dy) {
      for (int dx = -d; dx <= d; ++dx) {
        const double r = std::hypot(dx, dy);
        if (r <= kDenseRadius) taps.push_back({dx, dy, float(r), 1.0f, 1.0f});
      }
    }
    int ring = 0;
    for (double inner = kDenseRadius; inner < kMaxCocRadiusPx + 1; inner *= kRingRatio, ++ring) {
      const double outer = inner * kRingRatio, width = outer - inner, rho = 0.5 * (inner + outer);
      // As many taps as keep their spacing along the ring equal to the ring width.
      const int n = static_cast<int>(std::lround(2 * std::numbers::pi * rho / width));
      const double area = std::numbers::pi * (outer * outer - inner * inner) / n;
      const double phase = ring * 2.399963;  // golden angle: rings do not line up
      for (int k = 0; k < n; ++k) {
        const double a = phase + 2 * std::numbers::pi * k / n;
        const int dx = static_cast<int>(std::lround(rho * std::cos(a)));
        const int dy = static_cast<int>(std::lround(rho * std::sin(a)));
        taps.push_back({dx, dy, float(std::hypot(dx, dy)), float(area), float(1 / width)});
      }
    }
    std::stable_sort(taps.begin(), taps.end(),
                     [](const Tap& a, const Tap& b) { return a.distance < b.distance; });
    TapSet s;
    for (const Tap& t : taps) {
      s.dx.push_back(t.dx);
      s.dy.push_back(t.dy);
      s.distance.push_back(t.distance);
      s.area.push_back(t.area);
      s.inv_soft.push_back(t.inv_soft);
    }
    s.count_for_quarter.assign(4 * (kMaxCocRadiusPx + 1) + 1, 0);
    for (int q = 0; q < static_cast<int>(s.count_for_quarter.size()); ++q) {
      for (int t = 0; t < static_cast<int>(taps.size()); ++t) {
        if (taps[t].distance - 0.5f / taps[t].inv_soft < q / 4.0f) s.count_for_quarter[q] = t + 1;
      }
    }
    s.extent_of_count.assign(taps.size() + 1, 0);
    for (std::size_t t = 0; t < taps.size(); ++t) {
      s.extent_of_count[t + 1] =
          std::max({s.extent_of_count[t], std::abs(taps[t].dx), std::abs(taps[t].dy)});
    }
    return s;
  }();
  return set;
}

// A block of columns of a horizontal strip of the canvas as padded planes, so taps never need
// bounds checks. Padding pixels have no energy (inv_area 0) and sit in front of everything
// (z = -inf): they never contribute. Blocks keep the working set in cache (a whole frame's
// planes would not fit, nor would a strip's).
struct Planes {
  int pad = 0, stride = 0, x0 = 0, y0 = 0;  // the first image column and row they hold
  std::vector<float> r, g, b;
  std::vector<float> z;         // metres, +inf for unknown or background
  std::vector<float> radius;    // blur disc radius in pixels, at least 0.5 (a pixel's footprint)
  std::vector<float> inv_area;  // 1 / (π radius²): a pixel's energy per covered pixel
  std::size_t index(int x, int y) const {
    return static_cast<std::size_t>(y - y0 + pad) * stride + (x - x0 + pad);
  }
};

static_assert(kLanes == 8, "a group of pixels is one simd::F32x8");
using Floats = simd::F32x8;
using simd::load8;

// The gather's radius for a thin-lens disc of radius r: the one whose taps spread a uniform region
// with the disc's second moment, r²/2. The taps' coverage ramps spread a disc's edge over a
// pixel (the box the canvas's pixels already are), so the thin-lens radius itself blurs a disc of
// a pixel or two too much (1.6x the moment at 1 px), and a disc under a pixel reaches no
// neighbour at all; the paper scene's discs at f/5.6 are of those sizes.
class MatchedRadius {
 public:
  MatchedRadius() {
    const TapSet& set = tap_set();
    auto moment = [&set](double radius) {
      double weight = 0, weighted = 0;
      for (std::size_t t = 0; t < set.distance.size(); ++t) {
        const double d = set.distance[t];
        const double w = set.area[t] * std::clamp((radius - d) * set.inv_soft[t] + 0.5, 0.0, 1.0);
        weight += w;
        weighted += w * d * d;
      }
      return weighted / weight;
    };
    for (int k = 0; k <= kTableEnd * kPerPixel; ++k) {
      const double r = static_cast<double>(k) / kPerPixel;
      if (r < kSharpBelow) {
        table_.push_back(0.5f);
        continue;
      }
      double low = 0.5, high = r + 1;  // the moment grows with the radius from 0 at half a pixel
      for (int step = 0; step < 32; ++step) {
        const double mid = 0.5 * (low + high);
        (moment(mid) < 0.5 * r * r ? low : high) = mid;
      }
      table_.push_back(static_cast<float>(0.5 * (low + high)));
    }
    tail_sq_ = kTableEnd * kTableEnd - table_.back() * table_.back();
  }

  float operator()(float r) const {
    if (r < kSharpBelow) return 0.5f;
    if (!(r < kTableEnd)) return std::sqrt(r * r - tail_sq_);
    const float at = r * kPerPixel;
    const int k = static_cast<int>(at);
    return table_[k] + (at - static_cast<float>(k)) * (table_[k + 1] - table_[k]);
  }
  Floats operator()(Floats r) const {
    if (!simd::any(r < kTableEnd)) return simd::sqrt(r * r - tail_sq_);
    if (!simd::any(r >= kSharpBelow)) return Floats{} + 0.5f;
    Floats out;
    for (int k = 0; k < kLanes; ++k) out[k] = (*this)(r[k]);
    return out;
  }

 private:
  static constexpr int kPerPixel = 32;
  // Discs under half a pixel across stay sharp (their spread, under an eighth of a pixel, is not
  // worth gathering the in-focus regions for).
  static constexpr float kSharpBelow = 0.25f;
  // Beyond it the ramps add a constant (about a pixel's box): sqrt(r² - tail_sq_).
  static constexpr float kTableEnd = 8;
  std::vector<float> table_;  // [k]: the radius for r = k / kPerPixel
  float tail_sq_ = 0;
};

const MatchedRadius& matched_radius() {
  static const MatchedRadius matched;
  return matched;
}

inline Floats clamp01(Floats v) {
  const Floats zero = {}, one = zero + 1;
  v = v < zero ? zero : v;
  return v > one ? one : v;
}

struct GroupSums {
  Floats wf, ws, wb;  // front, same surface, behind
  Floats front[3], same[3], behind[3];
};

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

// `level` 0 is the canvas itself; level k gathers for the coarse tiles of level k - 1, on a frame
// half its size. Each step down and up adds the 2x2 box and the bilinear upsampling's blur
// (variance 1/3 + 2/3 px² at the finer level, 1/4 px² at the coarser), and the blur added above
// shrinks by 4 at each level, so level k removes 1 + 1/4 + ... (k terms) from r² to keep the
// total variance r²/4 of the thin-lens disc. Big discs thus cost about the same taps per pixel
// on a quarter of the pixels at each level.
constexpr int kMaxCoarseLevel = 3;

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

// One level of the depth of field: the canvas itself (level 0), or the half-size frame a level
// gathers its coarse tiles on.
struct LevelInput {
  const ir::Camera& camera;
  double focus_distance_m;
  Intrinsics canvas;
  std::span<const float> rgb, depth_m;
  std::span<float> out;  // may be `rgb`'s own values (in place)
  int level;
  // Tiles this level must produce: all of them at the top level (null); those the level above
  // samples below it. The output elsewhere is left as it is.
  const std::vector<char>* needed_tiles;
  const DepthOfFieldOptions& options;
  // Memory this level may use as it likes (contents unspecified), at least
  // coarse_output_values(w, h, level) values, or in_place_spare_values(w, h) in place. The
  // levels' outputs take its end (each level's output, then the levels below it); in place, its
  // start holds the half-size input and, once the levels below are done, the strips' kept border
  // rows.
  std::span<float> spare;
};

// The thin-lens radius in canvas pixels, factored as K·|1 - S1/z| (K: the radius at infinity)
// so the per-pixel cost is one division; z = +inf gives K. Less the blur the coarse levels above
// add, at full resolution as the taps' radius (MatchedRadius), at least half a pixel and at most
// kMaxCocRadiusPx. For one depth (float) or eight (Floats), with the same operations: the plane
// fill runs it eight at a time. Loops copy it into a local, so that their float stores need not
// reload its members.
struct BlurRadius {
  float radius_at_infinity = 0, focus = 0, removed_radius_sq = 0;
  const MatchedRadius* matched = &matched_radius();

  template <typename T>
  T operator()(T z) const {
    const T zero = T{}, half = zero + 0.5f, largest = zero + static_cast<float>(kMaxCocRadiusPx);
    T radius = radius_at_infinity * (1 - focus / z);
    radius = radius < zero ? -radius : radius;
    T square = radius * radius - removed_radius_sq;
    square = zero < square ? square : zero;
    T root;
    if constexpr (std::is_same_v<T, float>) {
      root = std::sqrt(square);
    } else {
      root = simd::sqrt(square);
    }
    if (matched != nullptr) root = (*matched)(root);
    return root < half ? half : (largest < root ? largest : root);
  }
};

// A strip's widest disc among the tiles it gathers, and the columns those tiles span (their taps
// read no further than the padding beyond).
struct StripPlan {
  float reach = 0.5f;
  int span_x0 = 0, span_x1 = 0;
  bool fills() const { return reach > 0.5f; }
};

// Written in place, a strip's rows would change under its neighbours' padding: before any strip
// writes, the rows within the padding of each border between strips are kept (those columns that
// a strip on either side reads), and the strips read them from there.
struct Halo {
  std::size_t offset = 0;  // into the kept values: rows first_row .. first_row + rows, x0 .. x1
  int first_row = 0, rows = 0, x0 = 0, x1 = 0;
};

// The rows of one strip and the rows of tiles they make.
struct StripRows {
  int y0, y1, ty0, ty1;
};

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

void keep_input(const LevelInput& in) {
  const bool in_place = in.rgb.data() == in.out.data() && in.rgb.size() == in.out.size();
  if (!in_place) std::copy(in.rgb.begin(), in.rgb.end(), in.out.begin());
}

void depth_of_field(const LevelInput& in);

// One level's work, in the order run() calls it: each tile's disc sizes and how far its discs
// reach; which tiles are flat, on one surface, or coarse; the coarse tiles on the level below;
// then strips of rows, each filled and gathered block by block.
class DepthOfFieldLevel {
 public:
  explicit DepthOfFieldLevel(const LevelInput& in);
  void run();

 private:
  bool active(std::size_t t) const { return in_.needed_tiles == nullptr || (*in_.needed_tiles)[t]; }
  std::size_t tile(int tx, int ty) const { return static_cast<std::size_t>(ty) * tiles_x_ + tx; }

  void measure_tiles();
  float spread_reach();
  void mark_flat_and_one_surface_tiles();
  void mark_coarse_tiles();

  void blur_coarse_tiles_at_half_size();
  void downsample_row(int hy, float* half_rgb, float* half_depth) const;
  std::vector<char> half_tiles_needed() const;
  int half_row_of(int y, float* weight) const;
  void upsample_tile(int x0, int x1, int y0, int y1) const;
  void upsample_interior_tile(int x0, int y0, int y1, int first) const;

  void plan_strips();
  void keep_halos();
  const float* input_row(int strip, int y, int* column_base) const;
  StripRows rows_of(int strip) const;

  void blur_strips();
  void blur_strip(int strip, std::array<Planes, 2>& block_planes, GroupSums& sums,
                  std::int64_t& groups_with_fewer_taps) const;
  void upsample_coarse_tiles(const StripRows& rows) const;
  void copy_sharp_tiles(const StripRows& rows) const;
  void fill_block(Planes& pl, const Planes* previous, int strip, const StripRows& rows, int bx0,
                  int bx1) const;
  void fill_row(Planes& pl, int strip, int y, int fill_x0, int fill_begin, int fill_end) const;
  void gather_tile(const Planes& pl, int tx, int ty, GroupSums& sums,
                   std::int64_t& groups_with_fewer_taps) const;

  const LevelInput& in_;
  const int w_, h_;
  // In place (`rgb` is `out`'s values): tiles that stay sharp are not touched at all, and the
  // start of `spare` holds the half-size input that the output holds otherwise.
  const bool in_place_;
  const std::size_t levels_values_;
  BlurRadius radius_at_;
  const int tiles_x_, tiles_y_;
  // Per tile: its largest and smallest disc, and the largest disc reaching it (0.5: none, or
  // flat and kept as it is).
  std::vector<float> tile_max_, tile_min_, reach_;
  TileRanges scanned_;
  const TileRanges* ranges_ = nullptr;
  std::vector<char> one_surface_, coarse_, part_coarse_;
  bool any_coarse_ = false;
  Intrinsics half_;
  // The half-size result, at the start of the levels' part of `spare` (the rest of it is the
  // level below's own spare memory).
  std::span<float> half_out_;
  const TapSet& set_;
  int pad_ = 0, strip_rows_ = 0, strips_ = 0;
  std::vector<StripPlan> plans_;
  std::vector<Halo> halos_;  // above strip k, in place
  float* halo_values_ = nullptr;
};

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

void depth_of_field(const LevelInput& in) {
  const double f = in.camera.focal_length_m;
  if (in.depth_m.size() != static_cast<std::size_t>(in.canvas.width) * in.canvas.height ||
      !(in.focus_distance_m > f) || !(f > 0)) {
    keep_input(in);
    return;
  }
  DepthOfFieldLevel(in).run();
}

}  // namespace

void apply_depth_of_field(const ir::Camera& camera, double focus_distance_m,
                          const Intrinsics& canvas, const std::vector<float>& rgb,
                          const std::vector<float>& depth_m, std::vector<float>& out,
                          const DepthOfFieldOptions& options) {
  if (options.groups_with_fewer_taps != nullptr) *options.groups_with_fewer_taps = 0;
  resize_frame_buffer(out, rgb.size());
  std::vector<float> spare = take_floats(coarse_output_values(canvas.width, canvas.height, 0));
  depth_of_field({camera, focus_distance_m, canvas, rgb, depth_m, out, 0, nullptr, options, spare});
  recycle(std::move(spare));
}

void apply_depth_of_field_in_place(const ir::Camera& camera, double focus_distance_m,
                                   const Intrinsics& canvas, std::vector<float>& rgb,
                                   const std::vector<float>& depth_m, std::vector<float>& spare,
                                   const DepthOfFieldOptions& options) {
  if (options.groups_with_fewer_taps != nullptr) *options.groups_with_fewer_taps = 0;
  const std::size_t needed = in_place_spare_values(canvas.width, canvas.height);
  if (spare.size() < needed) resize_frame_buffer(spare, needed);
  depth_of_field({camera, focus_distance_m, canvas, rgb, depth_m, rgb, 0, nullptr, options, spare});
}

}  // namespace rigc::dslr
