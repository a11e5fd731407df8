// Data passed through the DSLR pipeline: what a renderer hands in, what comes out.
#pragma once

#include <array>
#include <cstdint>
#include <vector>

namespace rigc::dslr {

// Pinhole intrinsics of a pixel grid. Pixel centres at +0.5 (COLMAP): pixel (i, j) has its
// centre at u = i + 0.5, and u = fx * x + cx for normalised camera coordinates x.
struct Intrinsics {
  int width = 0;
  int height = 0;
  double fx = 0, fy = 0, cx = 0, cy = 0;
};

// What a renderer must render: an undistorted pinhole canvas that covers every sensor pixel once
// the lens distortion is applied. `clipped` is set when the growth cap was hit (very strong
// distortion the compiler still takes): some sensor pixels then sample the canvas edge, and the
// capture advice says so at the distortion's line.
struct RenderGeometry : Intrinsics {
  bool clipped = false;
};

// What the depth of field first needs of a frame, per square tile of kTile pixels (the last
// row and column of tiles may be cut by the frame's edges): the nearest and furthest depth (a
// depth that is not > 0 counts as +inf, background) and each channel's smallest and largest
// radiance. A renderer that has its tiles in cache hands them over with the frame
// (record_tile_ranges, in depth_of_field.h); otherwise the depth of field reads the whole frame
// once more for them.
struct TileRanges {
  static constexpr int kTile = 16;
  int tiles_x = 0, tiles_y = 0;
  std::vector<float> near_m, far_m;  // per tile, row-major
  std::vector<float> radiance;       // 6 per tile: smallest r, g, b, then largest r, g, b

  void resize_for(int width, int height) {
    tiles_x = (width + kTile - 1) / kTile;
    tiles_y = (height + kTile - 1) / kTile;
    const std::size_t tiles = static_cast<std::size_t>(tiles_x) * tiles_y;
    near_m.resize(tiles);
    far_m.resize(tiles);
    radiance.resize(6 * tiles);
  }
  bool fits(int width, int height) const {
    const std::size_t tiles = static_cast<std::size_t>(tiles_x) * tiles_y;
    return tiles_x == (width + kTile - 1) / kTile && tiles_y == (height + kTile - 1) / kTile &&
           near_m.size() == tiles && far_m.size() == tiles && radiance.size() == 6 * tiles;
  }
};

// A linear frame from any renderer, rendered with an UNDISTORTED pinhole camera.
struct LinearFrame {
  int width = 0;
  int height = 0;
  double fx = 0, fy = 0, cx = 0, cy = 0;
  // 3 floats per pixel, row-major, top row first: scene-linear radiance in cd/m² (luminance
  // Y = 0.2126 R + 0.7152 G + 0.0722 B is in cd/m²).
  std::vector<float> rgb;
  // Camera-space z depth in metres per pixel; +inf for background at infinity.
  std::vector<float> depth_m;
  // Optional object mask (0 or 255); empty when the renderer has none.
  std::vector<std::uint8_t> mask;
  // Whether every rgb value is known to be finite and >= 0 (the preview renderer's frames). Such
  // a frame skips the exposure pass that would clean it: the exposure's scale is applied with the
  // vignetting gain instead, a multiply on values the warp writes anyway.
  bool rgb_clean = false;
  // Optional, for the depth of field: the ranges of exactly this rgb and depth_m (a renderer
  // that changes either afterwards clears them).
  TileRanges tile_ranges;

  Intrinsics intrinsics() const { return {width, height, fx, fy, cx, cy}; }
  // Takes the canvas's size and pinhole (the pixel buffers are left as they are).
  void set_intrinsics(const Intrinsics& canvas) {
    width = canvas.width;
    height = canvas.height;
    fx = canvas.fx;
    fy = canvas.fy;
    cx = canvas.cx;
    cy = canvas.cy;
  }
};

// Per-shot inputs that are not part of the camera.
struct ShotParams {
  double focus_distance_m = 1;  // ir::Shot::focus_distance_m
  int shot_index = 0;           // varies the temporal noise between shots
  std::uint64_t seed = 1;       // camera seed: fixes the sensor's fixed-pattern noise
  // Whether DevelopResult::depth_m is wanted (a writer of images only does not need it, and
  // the warp to the sensor then skips a frame-sized output).
  bool sensor_depth = true;
  // Whether DevelopResult::linear is wanted. Without it, and with a fixed white balance, the
  // sensor and the encoding run as one pass (the full-size linear image is never written).
  bool keep_linear = true;
};

// Wall-clock milliseconds spent in each stage of develop_frame.
struct StageTimings {
  double exposure_ms = 0;
  double depth_of_field_ms = 0;
  double diffraction_ms = 0;
  double distortion_ms = 0;  // warp to the sensor grid, with vignetting
  double noise_ms = 0;
  double develop_ms = 0;  // white balance, tone curve, encoding
  double total_ms = 0;
};

struct DevelopResult {
  int width = 0;
  int height = 0;
  // Normalised sensor signal (1.0 = clipping), 3 per pixel, after noise and before white
  // balance and the tone curve: the linear response tests can check against the formulas.
  std::vector<float> linear;
  int bits = 8;                        // 8 for JPEG, 16 for PNG/TIFF
  std::vector<std::uint16_t> encoded;  // sRGB code values, 3 per pixel (0..255 or 0..65535)
  // Instead of `encoded` (then empty) when the sensor and the encoding ran as one pass (8 bits,
  // ShotParams::keep_linear false, a fixed white balance): the codes as bytes, as a JPEG takes
  // them.
  std::vector<std::uint8_t> encoded_bytes;
  std::vector<std::uint8_t> mask;  // object mask on the sensor grid; empty if the frame had none
  std::vector<float> depth_m;      // depth on the sensor grid (nearest sample); see sensor_depth
  std::array<double, 3> white_balance_gains{1, 1, 1};
  StageTimings timings;
};

}  // namespace rigc::dslr
