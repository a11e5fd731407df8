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

// A dot's edge half-width: `edge`, narrowed where the dot would reach past half a cell.
float dot_edge(float radius, float edge) {
  return std::min(edge, 0.5f - radius);
}

// A dot's darkness at points `squared` (distance squared) from its centre.
F32x8 dot_darkness(F32x8 squared, float radius, float edge) {
  return smoothstep01((radius + edge - simd::sqrt(squared)) * (0.5f / edge));
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

// The dots of eight cells (a cell a lane): their centres' offsets within the cell and their radii.
struct CellDots {
  std::array<F32x8, kDotsPerCell> x, y, z, radius;
};

CellDots dots_of(F32x8 cx, F32x8 cy, F32x8 cz, float seed_offset) {
  const F32x8 hx = perm(mod289(cx) + seed_offset);
  const F32x8 hy = perm(hx + mod289(cy));
  const F32x8 hash = perm(hy + mod289(cz));
  CellDots dots;
  for (int dot = 0; dot < kDotsPerCell; ++dot) {
    const F32x8 g1 = perm(hash + kDotStarts[dot]);
    const F32x8 g2 = perm(g1 + 1);
    const F32x8 g3 = perm(g2 + 1);
    const F32x8 g4 = perm(g3 + 1);
    dots.x[dot] = g1 * (1 / kPrime);
    dots.y[dot] = g2 * (1 / kPrime);
    dots.z[dot] = g3 * (1 / kPrime);
    dots.radius[dot] = kRadiusMin + g4 * (kRadiusSpan / (kPrime - 1));
  }
  return dots;
}

// The darkest of the dots of `cells` at eight points (a point a lane), for one edge half-width.
// Each dot's darkness at a point comes from the same operations whichever other cells and points
// the call holds, and a dot of a cell outside a point's own 2 x 2 x 2 lies more than half a cell
// away, beyond its reach (radius + edge <= 0.48): a lane's result is its point's alone.
F32x8 darkness_among(F32x8 qx, F32x8 qy, F32x8 qz, const Cells& cells, float seed_offset,
                     float edge) {
  F32x8 darkness{};
  for (int g = 0; g < cells.groups; ++g) {
    const CellDots dots = dots_of(cells.x[g], cells.y[g], cells.z[g], seed_offset);
    const auto &gx = dots.x, &gy = dots.y, &gz = dots.z, &radius = dots.radius;
    for (int c = 0; c < 8; ++c) {
      const F32x8 dx = qx - cells.x[g][c], dy = qy - cells.y[g][c], dz = qz - cells.z[g][c];
      for (int dot = 0; dot < kDotsPerCell; ++dot) {
        const F32x8 ex = dx - gx[dot][c], ey = dy - gy[dot][c], ez = dz - gz[dot][c];
        const F32x8 squared = ex * ex + ey * ey + ez * ez;
        const float r = radius[dot][c];
        const float w = dot_edge(r, edge);
        // Most dots reach none of the points: their darkness there is 0.
        if (!simd::any(squared < (r + w) * (r + w))) continue;
        const F32x8 value = dot_darkness(squared, r, w);
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

namespace {

// What dots_over8 keeps of each lane: whether a dot covers all of its pixel, and the dots whose
// edges reach into it (their count past CrossingDots::kMost still counted).
struct LaneDots {
  explicit LaneDots(std::array<CrossingDots, 8>& crossing) : crossing(crossing) {
    for (CrossingDots& dots : crossing) dots.count = 0;
  }
  simd::I32x8 full{};
  std::array<CrossingDots, 8>& crossing;
};

// Calls visit(x, y, z, count) for the cells of the n[0] x n[1] x n[2] box from `first` that
// `wanted(x, y, z)` keeps, eight at a time, lanes [0, count) of x, y and z holding their
// coordinates.
template <typename Wanted, typename Visit>
void for_each_cell_group(const std::array<float, 3>& first, const std::array<int, 3>& n,
                         const Wanted& wanted, const Visit& visit) {
  F32x8 x{}, y{}, z{};
  int lane = 0;
  for (int k = 0; k < n[2]; ++k) {
    const float cz = first[2] + static_cast<float>(k);
    for (int j = 0; j < n[1]; ++j) {
      const float cy = first[1] + static_cast<float>(j);
      for (int i = 0; i < n[0]; ++i) {
        const float cx = first[0] + static_cast<float>(i);
        if (!wanted(cx, cy, cz)) continue;
        x[lane] = cx;
        y[lane] = cy;
        z[lane] = cz;
        if (++lane == 8) {
          visit(x, y, z, 8);
          lane = 0;
        }
      }
    }
  }
  if (lane > 0) visit(x, y, z, lane);
}

// What dots_over8 derives of each footprint: its sides' squared lengths and their dot product,
// and its reach, half the sum of the sides' lengths (no point of the pixel lies farther from its
// centre).
struct FootprintShape {
  explicit FootprintShape(const Footprints8& p)
      : dx_squared(p.dxx * p.dxx + p.dxy * p.dxy + p.dxz * p.dxz),
        dy_squared(p.dyx * p.dyx + p.dyy * p.dyy + p.dyz * p.dyz),
        sides_dot(p.dxx * p.dyx + p.dxy * p.dyy + p.dxz * p.dyz),
        reach(0.5f * (simd::sqrt(dx_squared) + simd::sqrt(dy_squared))) {}
  F32x8 dx_squared, dy_squared, sides_dot, reach;
};

F32x8 abs8(F32x8 v) {
  return v < 0 ? -v : v;
}
F32x8 max8(F32x8 a, F32x8 b) {
  return a > b ? a : b;
}

// Adds the dots of cells (x, y, z) [0, count) to the lanes of `lanes` that `active` selects.
// (Nine parameters: one group of lanes' registers, inlined into the gather loop.)
void gather_dots(const Footprints8& p, const FootprintShape& shape, simd::I32x8 active, F32x8 x,
                 F32x8 y, F32x8 z, int count, float seed_offset, LaneDots& lanes) {
  const F32x8 &dx_squared = shape.dx_squared, &dy_squared = shape.dy_squared, &reach = shape.reach;
  const CellDots dots_here = dots_of(x, y, z, seed_offset);
  for (int c = 0; c < count; ++c) {
    for (int dot = 0; dot < kDotsPerCell; ++dot) {
      const float r = dots_here.radius[dot][c];
      const float w = dot_edge(r, kEdge);
      const F32x8 ex = p.qx - (x[c] + dots_here.x[dot][c]),
                  ey = p.qy - (y[c] + dots_here.y[dot][c]),
                  ez = p.qz - (z[c] + dots_here.z[dot][c]);
      const F32x8 squared = ex * ex + ey * ey + ez * ez;
      const F32x8 reach_of_dot = r + w + reach;
      const simd::I32x8 maybe = active & (squared < reach_of_dot * reach_of_dot);
      if (!simd::any(maybe)) continue;
      const F32x8 d = simd::sqrt(squared);
      const F32x8 inverse = 1.0f / (d > 1e-12f ? d : F32x8{} + 1e-12f);
      const F32x8 along_x = p.dxx * ex + p.dxy * ey + p.dxz * ez;
      const F32x8 along_y = p.dyx * ex + p.dyy * ey + p.dyz * ez;
      const F32x8 half = 0.5f * (abs8(along_x) + abs8(along_y)) * inverse;
      // The distance over the pixel is at least d - half (its projection on the direction to the
      // point), and at most its largest at a corner: |e + s dx + t dy|^2 for s, t = +-1/2.
      const simd::I32x8 near = maybe & (d - half < r + w);
      const F32x8 corners = max8(abs8(along_x + along_y) + 0.5f * shape.sides_dot,
                                 abs8(along_x - along_y) - 0.5f * shape.sides_dot);
      const F32x8 farthest = squared + 0.25f * (dx_squared + dy_squared) + corners;
      const simd::I32x8 full = near & (farthest <= (r - w) * (r - w));
      lanes.full |= full;
      const simd::I32x8 crossing = near & ~full;
      if (!simd::any(crossing)) continue;
      for (int k = 0; k < 8; ++k) {
        if (!crossing[k]) continue;
        CrossingDots& dots = lanes.crossing[k];
        if (dots.count < CrossingDots::kMost) {
          dots.x[dots.count] = x[c] + dots_here.x[dot][c];
          dots.y[dots.count] = y[c] + dots_here.y[dot][c];
          dots.z[dots.count] = z[c] + dots_here.z[dot][c];
          dots.radius[dots.count] = r;
          dots.edge[dots.count] = w;
        }
        ++dots.count;
      }
    }
  }
}

// The cells from floor(v - 0.5 - reach) to floor(v - 0.5 + reach) + 1 of the lanes `active`
// selects, as the first and the count along one axis.
std::pair<float, int> cell_range(F32x8 v, F32x8 reach, simd::I32x8 active) {
  const F32x8 low = simd::floor(v - 0.5f - reach), high = simd::floor(v - 0.5f + reach) + 1;
  float first = 0, last = 0;
  bool any = false;
  for (int k = 0; k < 8; ++k) {
    if (!active[k]) continue;
    first = any ? std::min(first, low[k]) : low[k];
    last = any ? std::max(last, high[k]) : high[k];
    any = true;
  }
  return {first, static_cast<int>(last - first) + 1};
}

}  // namespace

unsigned dots_over8(const Footprints8& p, float seed_offset,
                    std::array<CrossingDots, 8>& crossing) {
  const FootprintShape shape(p);
  const F32x8& reach = shape.reach;
  LaneDots lanes(crossing);
  auto gather_for = [&](simd::I32x8 active) {
    const auto [x0, nx] = cell_range(p.qx, reach, active);
    const auto [y0, ny] = cell_range(p.qy, reach, active);
    const auto [z0, nz] = cell_range(p.qz, reach, active);
    // A cell's dots lie within half a cell of it: the cells no active pixel comes that near of
    // are left undrawn (the pixels lie on a surface, the box of cells spans a volume).
    const F32x8 low_x = p.qx - reach - 1.5f, high_x = p.qx + reach + 0.5f;
    const F32x8 low_y = p.qy - reach - 1.5f, high_y = p.qy + reach + 0.5f;
    const F32x8 low_z = p.qz - reach - 1.5f, high_z = p.qz + reach + 0.5f;
    auto wanted = [&](float cx, float cy, float cz) {
      return simd::any(active & (low_x < cx) & (cx < high_x) & (low_y < cy) & (cy < high_y) &
                       (low_z < cz) & (cz < high_z));
    };
    auto visit = [&](F32x8 x, F32x8 y, F32x8 z, int count) {
      gather_dots(p, shape, active, x, y, z, count, seed_offset, lanes);
    };
    for_each_cell_group({x0, y0, z0}, {nx, ny, nz}, wanted, visit);
  };
  // Pixels close together (as a rule) share their cells; scattered ones take theirs in turn.
  const simd::I32x8 all = simd::I32x8{} - 1;
  const auto [x0, nx] = cell_range(p.qx, reach, all);
  const auto [y0, ny] = cell_range(p.qy, reach, all);
  const auto [z0, nz] = cell_range(p.qz, reach, all);
  if (nx * ny * nz <= 64) {
    gather_for(all);
  } else {
    for (int k = 0; k < 8; ++k) {
      simd::I32x8 one{};
      one[k] = -1;
      gather_for(one);
    }
  }
  unsigned full = 0;
  for (int k = 0; k < 8; ++k) {
    if (lanes.full[k]) full |= 1u << k;
    if (crossing[k].count > CrossingDots::kMost) crossing[k].count = -1;
  }
  return full;
}

F32x8 darkness_of8(F32x8 qx, F32x8 qy, F32x8 qz, const CrossingDots& dots) {
  F32x8 darkness{};
  for (int i = 0; i < dots.count; ++i) {
    const F32x8 ex = qx - dots.x[i], ey = qy - dots.y[i], ez = qz - dots.z[i];
    const F32x8 value = dot_darkness(ex * ex + ey * ey + ez * ez, dots.radius[i], dots.edge[i]);
    darkness = value > darkness ? value : darkness;
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
