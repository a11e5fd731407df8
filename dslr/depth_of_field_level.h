// The parts of one level of the depth of field (dslr/depth_of_field.h) that its stages share:
// the tap set, the padded planes, the disc radius, a level's input and the level itself. Only
// the depth_of_field*.cpp files include it: depth_of_field.cpp (the tiles and the driver),
// depth_of_field_taps.cpp, depth_of_field_coarse.cpp (half size) and depth_of_field_strips.cpp
// (the gather).
#pragma once

#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <span>
#include <type_traits>
#include <vector>

#include "dslr/depth_of_field.h"
#include "dslr/simd.h"

// (For the files that include this.) The 32-byte vectors of the gather are only passed between
// functions inlined into the AVX2 and the default clone of one function, so GCC's note on their ABI
// without AVX does not apply.
#pragma GCC diagnostic ignored "-Wpsabi"

namespace rigc::dslr::dof {

constexpr int kTile = 16;            // pixels per side of a tile that shares one tap count
constexpr int kLanes = 8;            // pixels gathered together (one AVX register)
constexpr float kSameDepth = 0.02f;  // relative depth band counted as "the same surface"
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

// The taps, built once.
const TapSet& tap_set();

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
  MatchedRadius();

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

// The table, built once.
const MatchedRadius& matched_radius();

struct GroupSums {
  Floats wf, ws, wb;  // front, same surface, behind
  Floats front[3], same[3], behind[3];
};

// `level` 0 is the canvas itself; level k gathers for the coarse tiles of level k - 1, on a frame
// half its size. Each step down and up adds the 2x2 box and the bilinear upsampling's blur
// (variance 1/3 + 2/3 px² at the finer level, 1/4 px² at the coarser), and the blur added above
// shrinks by 4 at each level, so level k removes 1 + 1/4 + ... (k terms) from r² to keep the
// total variance r²/4 of the thin-lens disc. Big discs thus cost about the same taps per pixel
// on a quarter of the pixels at each level.
constexpr int kMaxCoarseLevel = 3;

// The values the coarse levels below a w x h frame at `level` take for their outputs: three per
// pixel of each half-size frame down to kMaxCoarseLevel.
std::size_t coarse_output_values(int w, int h, int level);

// The values an in-place call at the top level needs in its spare memory: the half-size input
// (four per half-size pixel) and the levels' outputs after it.
std::size_t in_place_spare_values(int w, int h);

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

// `in.rgb` into `in.out` (nothing to do in place): a level where everything is sharp.
void keep_input(const LevelInput& in);

// One level: checks the input, then DepthOfFieldLevel(in).run().
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

}  // namespace rigc::dslr::dof
