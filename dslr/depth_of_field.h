// Depth of field: the thin-lens disc blur, applied to the undistorted canvas
// (docs/camera-model.md).
#pragma once

#include <cstdint>
#include <vector>

#include "dslr/frame.h"
#include "ir/ir.h"

namespace rigc::dslr {

// Blur discs are capped at this radius (pixels of the canvas): beyond it the blur is
// underestimated (documented approximation that bounds the cost).
inline constexpr int kMaxCocRadiusPx = 64;

// Depth of field on an undistorted canvas (rgb: 3 per pixel, depth_m: 1 per pixel).
//
// A scatter-as-gather disc blur: pixel p collects every neighbour q whose blur disc covers it.
// Neighbours are split by depth into three layers composited front to back:
//  - in front of p: q's own disc decides (a blurred foreground spreads over a sharp background);
//    its weight is q's energy per pixel, 1/(π r_q²), and the summed coverage is the layer's alpha;
//  - at p's depth (±2 %): the same, normalised (a uniform region gets the plain disc average);
//  - behind p: only within p's own disc, so a sharp foreground never picks up the background
//    behind it and keeps its exact values (no halos).
// Approximations: taps are every pixel within 4.5 px, then rings 30 % apart with as many taps
// as keep the spacing isotropic, each weighted by the area it stands for and rounded to whole
// pixels (large discs of small bright highlights show ring structure); discs are capped at
// kMaxCocRadiusPx. Each 16x16 tile only visits the taps that the largest disc reaching it needs,
// so sharp regions cost a copy and the cost grows with the blur.
// Where several depths meet, each group of eight pixels narrows that further to the taps its own
// discs and the discs not behind it can reach (the rest add exact zeros), and takes the cheaper
// one-surface arithmetic for the taps that no front disc and no pixel behind it reaches.
struct DepthOfFieldOptions {
  // False: every group gathers its tile's taps, all in three layers (tests compare the two; the
  // sums are the same).
  bool taps_per_group = true;
  // If set, receives how many groups gathered fewer taps than their tile.
  std::int64_t* groups_with_fewer_taps = nullptr;
  // If set and the frame's size, the ranges of `rgb` and `depth_m` (LinearFrame::tile_ranges):
  // the frame is not scanned for them.
  const TileRanges* tile_ranges = nullptr;
};
// Fills `ranges` (sized by resize_for) for the tiles inside [x0, x1) x [y0, y1) of a frame
// `width` pixels wide: x0 and y0 multiples of TileRanges::kTile, x1 and y1 too or the frame's
// edges.
// (Eight parameters: a rectangle of a frame's two planes; the renderer calls it per strip.)
void record_tile_ranges(const float* rgb, const float* depth_m, int width, int x0, int y0, int x1,
                        int y1, TileRanges& ranges);

// The blurred canvas into `out`.
// (Seven parameters, the last optional: the camera, the canvas and its planes.)
void apply_depth_of_field(const ir::Camera& camera, double focus_distance_m,
                          const Intrinsics& canvas, const std::vector<float>& rgb,
                          const std::vector<float>& depth_m, std::vector<float>& out,
                          const DepthOfFieldOptions& options = {});
// The same result, written over `rgb`: tiles that stay sharp are not copied. `spare` (contents
// unspecified; grown to about two thirds of `rgb` when it is smaller, never shrunk) holds the
// half-size frames of the big discs and the strips' kept border rows meanwhile.
// (Seven parameters, the last optional: the camera, the canvas and its planes.)
void apply_depth_of_field_in_place(const ir::Camera& camera, double focus_distance_m,
                                   const Intrinsics& canvas, std::vector<float>& rgb,
                                   const std::vector<float>& depth_m, std::vector<float>& spare,
                                   const DepthOfFieldOptions& options = {});

}  // namespace rigc::dslr
