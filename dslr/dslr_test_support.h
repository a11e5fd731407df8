// Cameras and synthetic frames for the DSLR tests (used by dslr/*_test.cpp only).
#pragma once

#include <cmath>
#include <limits>
#include <vector>

#include "dslr/frame.h"
#include "dslr/lens.h"
#include "ir/ir.h"

namespace rigc::dslr::testing {

// A Canon EOS 6D with a 50 mm lens, intrinsics as the compiler lowers them, every effect off.
inline ir::Camera canon_6d() {
  ir::Camera camera;
  camera.body = "canon-6d";
  camera.make = "Canon";
  camera.model = "Canon EOS 6D";
  camera.fx = camera.focal_length_m * camera.width_px / camera.sensor_width_m;
  camera.fy = camera.focal_length_m * camera.height_px / camera.sensor_height_m;
  camera.cx = camera.width_px / 2.0;
  camera.cy = camera.height_px / 2.0;
  camera.effects = {false, false, false, false, false, false};
  camera.white_balance = ir::WhiteBalanceMode::kKelvin;
  camera.white_balance_k = 6504;
  return camera;
}

// A frame on the given grid, uniform luminance (grey) and depth.
inline LinearFrame flat_frame(const Intrinsics& k, float luminance, float depth_m) {
  LinearFrame frame;
  frame.width = k.width;
  frame.height = k.height;
  frame.fx = k.fx;
  frame.fy = k.fy;
  frame.cx = k.cx;
  frame.cy = k.cy;
  const std::size_t n = static_cast<std::size_t>(k.width) * k.height;
  frame.rgb.assign(3 * n, luminance);
  frame.depth_m.assign(n, depth_m);
  return frame;
}

inline double mean_of(const std::vector<float>& v, int channel = -1) {
  double sum = 0;
  std::size_t count = 0;
  for (std::size_t i = 0; i < v.size(); ++i) {
    if (channel >= 0 && static_cast<int>(i % 3) != channel) continue;
    sum += v[i];
    ++count;
  }
  return sum / count;
}

}  // namespace rigc::dslr::testing
