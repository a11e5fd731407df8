// Colour helpers shared by the compiler and the renderers.
#pragma once

#include "ir/ir.h"

namespace rigc {

// Linear sRGB colour of a blackbody at `kelvin` (1000..40000 K), scaled to luminance Y = 1.
// Planckian locus in CIE xy by Kang et al. (2002), then XYZ -> linear sRGB (D65).
ir::Vec3 blackbody_linear_srgb(double kelvin);

// Relative luminance of linear sRGB.
inline double luminance(const ir::Vec3& rgb) {
  return 0.2126 * rgb.x() + 0.7152 * rgb.y() + 0.0722 * rgb.z();
}

}  // namespace rigc
