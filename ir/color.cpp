#include "ir/color.h"

#include <algorithm>
#include <cmath>

namespace rigc {

ir::Vec3 blackbody_linear_srgb(double kelvin) {
  const double t = std::clamp(kelvin, 1667.0, 25000.0);
  const double t2 = t * t, t3 = t2 * t;
  double x;
  if (t <= 4000) {
    x = -0.2661239e9 / t3 - 0.2343589e6 / t2 + 0.8776956e3 / t + 0.179910;
  } else {
    x = -3.0258469e9 / t3 + 2.1070379e6 / t2 + 0.2226347e3 / t + 0.240390;
  }
  const double x2 = x * x, x3 = x2 * x;
  double y;
  if (t <= 2222) {
    y = -1.1063814 * x3 - 1.34811020 * x2 + 2.18555832 * x - 0.20219683;
  } else if (t <= 4000) {
    y = -0.9549476 * x3 - 1.37418593 * x2 + 2.09137015 * x - 0.16748867;
  } else {
    y = 3.0817580 * x3 - 5.87338670 * x2 + 3.75112997 * x - 0.37001483;
  }
  const double X = x / y, Y = 1.0, Z = (1 - x - y) / y;
  ir::Vec3 rgb(3.2404542 * X - 1.5371385 * Y - 0.4985314 * Z,
               -0.9692660 * X + 1.8760108 * Y + 0.0415560 * Z,
               0.0556434 * X - 0.2040259 * Y + 1.0572252 * Z);
  rgb = rgb.cwiseMax(0.0);
  return rgb / luminance(rgb);
}

}  // namespace rigc
