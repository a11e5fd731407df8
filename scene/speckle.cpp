#include "scene/speckle.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <utility>

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

// Cells with integer coordinates, eight a group (a cell a lane); the last group's spare lanes
// repeat its last cell.
struct Cells {
  static constexpr int kMostGroups = 4;  // 27 cells: three an axis
  std::array<F32x8, kMostGroups> x{}, y{}, z{};
  int groups = 0;
};

// The n[0] x n[1] x n[2] cells from `first` on, n at most 3 an axis.
Cells cells_from(const std::array<float, 3>& first, const std::array<int, 3>& n) {
  Cells cells;
  int lane = 0;
  for (int k = 0; k < n[2]; ++k) {
    for (int j = 0; j < n[1]; ++j) {
      for (int i = 0; i < n[0]; ++i) {
        if (lane == 0) ++cells.groups;
        const int g = cells.groups - 1;
        cells.x[g][lane] = first[0] + static_cast<float>(i);
        cells.y[g][lane] = first[1] + static_cast<float>(j);
        cells.z[g][lane] = first[2] + static_cast<float>(k);
        lane = (lane + 1) % 8;
      }
    }
  }
  for (const int g = cells.groups - 1; lane != 0 && lane < 8; ++lane) {
    cells.x[g][lane] = cells.x[g][lane - 1];
    cells.y[g][lane] = cells.y[g][lane - 1];
    cells.z[g][lane] = cells.z[g][lane - 1];
  }
  return cells;
}

// The darkest of the dots of `cells` at eight points (a point a lane), for one edge half-width.
// Each dot's darkness at a point comes from the same operations whichever other cells and points
// the call holds, and a dot of a cell outside a point's own 2 x 2 x 2 lies more than half a cell
// away, beyond its reach (radius + edge <= 0.48): a lane's result is its point's alone.
F32x8 darkness_among(F32x8 qx, F32x8 qy, F32x8 qz, const Cells& cells, float seed_offset,
                     float edge) {
  F32x8 darkness{};
  for (int g = 0; g < cells.groups; ++g) {
    const F32x8 hx = perm(mod289(cells.x[g]) + seed_offset);
    const F32x8 hy = perm(hx + mod289(cells.y[g]));
    const F32x8 hash = perm(hy + mod289(cells.z[g]));
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
    for (int c = 0; c < 8; ++c) {
      const F32x8 dx = qx - cells.x[g][c], dy = qy - cells.y[g][c], dz = qz - cells.z[g][c];
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
  }
  return darkness;
}

// The lowest value of `v`'s lanes and how many cells from it its 2 x 2 x 2 blocks span.
std::pair<float, int> block_span(F32x8 v) {
  float low = v[0], high = v[0];
  for (int k = 1; k < 8; ++k) {
    low = std::min(low, v[k]);
    high = std::max(high, v[k]);
  }
  return {low, static_cast<int>(high - low) + 2};
}

}  // namespace

F32x8 darkness8(F32x8 qx, F32x8 qy, F32x8 qz, float seed_offset, F32x8 edge) {
  const F32x8 bx = simd::floor(qx - 0.5f), by = simd::floor(qy - 0.5f), bz = simd::floor(qz - 0.5f);
  // Points close together (a pixel's filter samples, as a rule): their cells' dots drawn once.
  const auto [x0, nx] = block_span(bx);
  const auto [y0, ny] = block_span(by);
  const auto [z0, nz] = block_span(bz);
  if (nx <= 3 && ny <= 3 && nz <= 3 && !simd::any(edge != edge[0])) {
    return darkness_among(qx, qy, qz, cells_from({x0, y0, z0}, {nx, ny, nz}), seed_offset, edge[0]);
  }
  // Otherwise each lane's own 2 x 2 x 2 cells in turn, shared with the lanes of the same cells.
  F32x8 darkness{};
  unsigned done = 0;
  for (int k = 0; k < 8; ++k) {
    if (done >> k & 1u) continue;
    const F32x8 value = darkness_among(qx, qy, qz, cells_from({bx[k], by[k], bz[k]}, {2, 2, 2}),
                                       seed_offset, edge[k]);
    for (int m = k; m < 8; ++m) {
      if (!(done >> m & 1u) && bx[m] == bx[k] && by[m] == by[k] && bz[m] == bz[k] &&
          edge[m] == edge[k]) {
        darkness[m] = value[m];
        done |= 1u << m;
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
