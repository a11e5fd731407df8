#include "scene/speckle.h"

#include <algorithm>
#include <array>
#include <cmath>

namespace rigc::scene::speckle {

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

namespace {

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

// darkness8 where every lane's point has the same 2 x 2 x 2 cells and edge (a pixel's filter
// samples, as a rule): the cells' hashes and dots are computed once, a cell a lane, then each
// dot's darkness at the eight points where it reaches one.
F32x8 darkness8_one_block(F32x8 qx, F32x8 qy, F32x8 qz, float bx, float by, float bz,
                          float seed_offset, float edge) {
  const F32x8 cell_i = {0, 1, 0, 1, 0, 1, 0, 1}, cell_j = {0, 0, 1, 1, 0, 0, 1, 1},
              cell_k = {0, 0, 0, 0, 1, 1, 1, 1};
  const F32x8 hx = perm(mod289(mod289(F32x8{} + bx) + cell_i) + seed_offset);
  const F32x8 hy = perm(hx + mod289(mod289(F32x8{} + by) + cell_j));
  const F32x8 hash = perm(hy + mod289(mod289(F32x8{} + bz) + cell_k));
  std::array<F32x8, kDotsPerCell> gx, gy, gz, radius;
  for (int dot = 0; dot < kDotsPerCell; ++dot) {
    const F32x8 g1 = perm(hash + kDotStarts[dot]);
    const F32x8 g2 = perm(g1 + 1);
    const F32x8 g3 = perm(g2 + 1);
    const F32x8 g4 = perm(g3 + 1);
    gx[dot] = g1 * (1 / kPrime);
    gy[dot] = g2 * (1 / kPrime);
    gz[dot] = g3 * (1 / kPrime);
    radius[dot] = kRadiusMin + g4 * (kRadiusSpan / (kPrime - 1));
  }
  F32x8 darkness{};
  for (int c = 0; c < 8; ++c) {
    const F32x8 dx = qx - (bx + cell_i[c]), dy = qy - (by + cell_j[c]), dz = qz - (bz + cell_k[c]);
    for (int dot = 0; dot < kDotsPerCell; ++dot) {
      const F32x8 ex = dx - gx[dot][c], ey = dy - gy[dot][c], ez = dz - gz[dot][c];
      const F32x8 squared = ex * ex + ey * ey + ez * ez;
      const float r = radius[dot][c];
      const float w = std::min(edge, 0.5f - r);
      // Most dots reach none of the points: their darkness there is 0.
      if (!simd::any(squared < (r + w) * (r + w))) continue;
      const F32x8 value = smoothstep01((r + w - simd::sqrt(squared)) * (0.5f / w));
      darkness = value > darkness ? value : darkness;
    }
  }
  return darkness;
}

}  // namespace

F32x8 darkness8(F32x8 qx, F32x8 qy, F32x8 qz, float seed_offset, F32x8 edge) {
  const F32x8 bx = simd::floor(qx - 0.5f), by = simd::floor(qy - 0.5f), bz = simd::floor(qz - 0.5f);
  if (!simd::any((bx != bx[0]) | (by != by[0]) | (bz != bz[0]) | (edge != edge[0]))) {
    return darkness8_one_block(qx, qy, qz, bx[0], by[0], bz[0], seed_offset, edge[0]);
  }
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

namespace rigc::scene::noise {
namespace {

using simd::F32x8;

// value(q, s) of speckle.h: the cell's corner hashes blended trilinearly.
F32x8 value8(F32x8 qx, F32x8 qy, F32x8 qz, float seed_offset) {
  using speckle::mod289;
  using speckle::perm;
  const F32x8 fx = simd::floor(qx), fy = simd::floor(qy), fz = simd::floor(qz);
  auto fade = [](F32x8 t) { return t * t * (3 - 2 * t); };
  const F32x8 tx = fade(qx - fx), ty = fade(qy - fy), tz = fade(qz - fz);
  const F32x8 wx = mod289(fx), wy = mod289(fy), wz = mod289(fz);
  std::array<F32x8, 8> corner;
  for (int c = 0; c < 8; ++c) {
    const F32x8 hx = perm(mod289(wx + static_cast<float>(c & 1)) + seed_offset);
    const F32x8 hy = perm(hx + mod289(wy + static_cast<float>((c >> 1) & 1)));
    corner[c] =
        perm(hy + mod289(wz + static_cast<float>((c >> 2) & 1))) * (1 / (speckle::kPrime - 1));
  }
  auto mix = [](F32x8 a, F32x8 b, F32x8 t) { return a + (b - a) * t; };
  const F32x8 y0 = mix(mix(corner[0], corner[1], tx), mix(corner[2], corner[3], tx), ty);
  const F32x8 y1 = mix(mix(corner[4], corner[5], tx), mix(corner[6], corner[7], tx), ty);
  return mix(y0, y1, tz);
}

}  // namespace

F32x8 darkness8(F32x8 qx, F32x8 qy, F32x8 qz, std::uint32_t seed) {
  F32x8 n{};
  for (int k = 0; k < kOctaves; ++k) {
    const float f = kFrequencies[k];
    n += kAmplitudes[k] * value8(qx * f, qy * f, qz * f, speckle::seed_offset(seed + k));
  }
  return n * (1 / kAmplitudeSum);
}

double darkness_reference(double qx, double qy, double qz, std::uint32_t seed) {
  const double p = speckle::kPrime;
  auto perm = [&](double v) { return std::fmod((34 * v + 1) * v, p); };
  auto wrap = [&](double c) { return std::fmod(std::fmod(c, p) + p, p); };
  auto fade = [](double t) { return t * t * (3 - 2 * t); };
  double n = 0;
  for (int k = 0; k < kOctaves; ++k) {
    const double s = speckle::seed_offset(seed + k);
    const double x = qx * static_cast<double>(kFrequencies[k]),
                 y = qy * static_cast<double>(kFrequencies[k]),
                 z = qz * static_cast<double>(kFrequencies[k]);
    const double fx = std::floor(x), fy = std::floor(y), fz = std::floor(z);
    double value = 0;
    for (int c = 0; c < 8; ++c) {
      const int ix = c & 1, iy = (c >> 1) & 1, iz = (c >> 2) & 1;
      const double lattice =
          perm(perm(perm(wrap(fx + ix) + s) + wrap(fy + iy)) + wrap(fz + iz)) / (p - 1);
      const double w = (ix ? fade(x - fx) : 1 - fade(x - fx)) *
                       (iy ? fade(y - fy) : 1 - fade(y - fy)) *
                       (iz ? fade(z - fz) : 1 - fade(z - fz));
      value += w * lattice;
    }
    n += kAmplitudes[k] * value;
  }
  return n / kAmplitudeSum;
}

}  // namespace rigc::scene::noise
