#include "scene/speckle.h"

#include <algorithm>
#include <cmath>

namespace rigc::scene::speckle {
namespace {

using simd::F32x8;

// x mod 289 for integer-valued x with |x| < 2^24: the quotient's rounding is corrected, so the
// result is exact (as C's fmod is).
F32x8 mod289(F32x8 x) {
  F32x8 r = x - kPrime * simd::floor(x * (1 / kPrime));
  r += (r < 0) ? F32x8{} + kPrime : F32x8{};
  r -= (r >= kPrime) ? F32x8{} + kPrime : F32x8{};
  return r;
}

// (34 v + 1) v < 2^24 for v < 578: exact in float.
F32x8 perm(F32x8 v) {
  return mod289((34 * v + 1) * v);
}

F32x8 smoothstep01(F32x8 t) {
  t = t < 0 ? F32x8{} : t;
  t = t > 1 ? F32x8{} + 1 : t;
  return t * t * (3 - 2 * t);
}

// The darkest of the cell's dots at offset (dx, dy, dz) from its corner.
F32x8 cell_darkness(F32x8 dx, F32x8 dy, F32x8 dz, F32x8 hash, F32x8 edge) {
  F32x8 darkness{};
  for (const float start : kDotStarts) {
    const F32x8 g1 = perm(hash + start);
    const F32x8 g2 = perm(g1 + 1);
    const F32x8 g3 = perm(g2 + 1);
    const F32x8 g4 = perm(g3 + 1);
    const F32x8 ex = dx - g1 * (1 / kPrime), ey = dy - g2 * (1 / kPrime),
                ez = dz - g3 * (1 / kPrime);
    const F32x8 dist = simd::sqrt(ex * ex + ey * ey + ez * ez);
    const F32x8 radius = kRadiusMin + g4 * (kRadiusSpan / (kPrime - 1));
    // A dot ends within half a cell of its centre (see speckle.h).
    const F32x8 room = 0.5f - radius;
    const F32x8 w = edge < room ? edge : room;
    const F32x8 dot = smoothstep01((radius + w - dist) / (2 * w));
    darkness = dot > darkness ? dot : darkness;
  }
  return darkness;
}

}  // namespace

F32x8 darkness8(F32x8 qx, F32x8 qy, F32x8 qz, float seed_offset, F32x8 edge) {
  const F32x8 bx = simd::floor(qx - 0.5f), by = simd::floor(qy - 0.5f), bz = simd::floor(qz - 0.5f);
  const F32x8 wx = mod289(bx), wy = mod289(by), wz = mod289(bz);
  F32x8 darkness{};
  for (int i = 0; i < 2; ++i) {
    const F32x8 hx = perm(mod289(wx + static_cast<float>(i)) + seed_offset);
    for (int j = 0; j < 2; ++j) {
      const F32x8 hy = perm(hx + mod289(wy + static_cast<float>(j)));
      for (int k = 0; k < 2; ++k) {
        const F32x8 hash = perm(hy + mod289(wz + static_cast<float>(k)));
        const F32x8 cell =
            cell_darkness(qx - (bx + static_cast<float>(i)), qy - (by + static_cast<float>(j)),
                          qz - (bz + static_cast<float>(k)), hash, edge);
        darkness = cell > darkness ? cell : darkness;
      }
    }
  }
  return darkness;
}

double darkness_reference(double qx, double qy, double qz, double seed_offset, double edge) {
  const double p = kPrime;
  auto perm = [&](double v) { return std::fmod((34 * v + 1) * v, p); };
  auto wrap = [&](double c) { return std::fmod(std::fmod(c, p) + p, p); };
  double darkness = 0;
  for (int corner = 0; corner < 8; ++corner) {
    const double cx = std::floor(qx - 0.5) + (corner & 1);
    const double cy = std::floor(qy - 0.5) + ((corner >> 1) & 1);
    const double cz = std::floor(qz - 0.5) + ((corner >> 2) & 1);
    const double hash = perm(perm(perm(wrap(cx) + seed_offset) + wrap(cy)) + wrap(cz));
    for (const float start : kDotStarts) {
      const double g1 = perm(hash + start), g2 = perm(g1 + 1), g3 = perm(g2 + 1), g4 = perm(g3 + 1);
      const double dist = std::sqrt(std::pow(qx - cx - g1 / p, 2) + std::pow(qy - cy - g2 / p, 2) +
                                    std::pow(qz - cz - g3 / p, 2));
      const double radius = kRadiusMin + kRadiusSpan * g4 / (p - 1);
      const double w = std::min(edge, 0.5 - radius);
      const double t = std::clamp((radius + w - dist) / (2 * w), 0.0, 1.0);
      darkness = std::max(darkness, t * t * (3 - 2 * t));
    }
  }
  return darkness;
}

}  // namespace rigc::scene::speckle
