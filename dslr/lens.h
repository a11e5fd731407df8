// The lens between the pinhole render and the sensor: Brown-Conrady distortion (OpenCV order
// k1 k2 p1 p2 k3, COLMAP's OPENCV model) and vignetting.
#pragma once

#include <cstdint>
#include <vector>

#include "dslr/frame.h"
#include "ir/ir.h"

namespace rigc::dslr {

// The sensor image at `scale` (width_px·scale x height_px·scale, rounded) and its intrinsics,
// scaled with it. Falls back to f·width/sensor_width and the image centre when the camera has
// no pixel intrinsics.
Intrinsics sensor_intrinsics(const ir::Camera& camera, double scale);

// The camera a render at `scale` simulates: the sensor's size and every setting kept, its pixel
// grid and intrinsics those of sensor_intrinsics (so its pixels are 1/scale as wide, each with
// the noise of one of the camera's own, as the run develops it).
ir::Camera camera_at_scale(const ir::Camera& camera, double scale);

// Undistorted -> distorted normalised coordinates (docs/camera-model.md, OpenCV).
ir::Vec2 distort_normalized(const ir::Distortion& d, double x, double y);

// Distorted -> undistorted, by Newton's method (converges to ~1e-14). Returns false when the
// point is beyond the fold of the distortion (no undistorted point maps there); `guess`, if
// given, is the starting point (a neighbour's solution makes one or two steps enough).
bool try_undistort_normalized(const ir::Distortion& d, double x, double y, ir::Vec2* undistorted,
                              const ir::Vec2* guess = nullptr);
// Same, returning the input unchanged when there is no solution.
ir::Vec2 undistort_normalized(const ir::Distortion& d, double x, double y);

// The undistorted canvas a renderer must render: every sensor pixel (at `scale`) maps inside
// it after distortion, with a 2-pixel margin for bilinear sampling. Same focal lengths as the
// sensor; each side grows by at most half the sensor size. Equals the sensor grid when the
// distortion effect is off or the coefficients are zero.
RenderGeometry render_geometry_for(const ir::Camera& camera, double scale);

// Light kept at normalised radius² r2 (on the sensor): a cos⁴-like falloff 1/(1+r²)², rescaled so
// the centre keeps 1 and r2_corner keeps 1 - fraction_lost.
double vignetting_gain(double fraction_lost, double r2, double r2_corner);

struct SensorImage {
  Intrinsics intrinsics;
  std::vector<float> rgb;          // 3 per pixel
  std::vector<float> depth_m;      // nearest sample; +inf where nothing maps
  std::vector<std::uint8_t> mask;  // nearest sample; empty if the canvas has none
};

// Resamples the canvas onto the sensor grid: for each sensor pixel, undistort its normalised
// coordinates and sample the canvas (bilinear for colour, nearest for depth and mask), then apply
// vignetting. camera.effects.distortion / .vignetting switch the two effects.
// `storage`, if given, is a spare buffer reused for the output colour (no fresh pages to fault in).
// `signal_scale` multiplies the colour with the vignetting gain (the exposure, when the canvas
// holds radiance).
// (Eight parameters, two optional: the grids, the frame's three planes, a reused buffer and a
// gain; a frame struct would be made only to be taken apart.)
SensorImage warp_to_sensor(const ir::Camera& camera, const Intrinsics& sensor,
                           const Intrinsics& canvas, const std::vector<float>& rgb,
                           const std::vector<float>& depth_m, const std::vector<std::uint8_t>& mask,
                           std::vector<float> storage = {}, double signal_scale = 1);

}  // namespace rigc::dslr
