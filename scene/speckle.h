// The `speckle` pattern: round dark dots scattered at random, one function of the object-frame
// point that every renderer evaluates alike (the preview here, POV-Ray as SDL functions, Cycles
// as shader nodes; backends/ write those from the constants below).
//
// In units of the pattern's scale (q = p / scale), space is cut into unit cells; each cell holds
// kDotsPerCell dots, each with a centre and radius drawn from the cell's integer coordinates by
// a permutation polynomial modulo 289 (exact in float and double, so every renderer draws the
// same dots). A dot's darkness falls from 1 to 0 over a smoothstep edge of half-width `edge`
// about its radius; the pattern is the darkest dot at the point. No dot reaches further than
// half a cell from its centre, so the 2 x 2 x 2 cells around the point hold every dot there.
//
//   perm(v)          = mod((34 v + 1) v, 289)                v an integer in [0, 578)
//   wrap(c)          = mod(mod(c, 289) + 289, 289)           (mod: C's fmod, exact here)
//   hash(c)          = perm(perm(perm(wrap(cx) + seed) + wrap(cy)) + wrap(cz))
//   dot k of cell c: g1 = perm(hash + kDotStarts[k]), g2 = perm(g1 + 1), g3 = perm(g2 + 1),
//                    g4 = perm(g3 + 1); centre c + (g1, g2, g3) / 289,
//                    radius kRadiusMin + kRadiusSpan · g4 / 288
//   darkness         = max over the dots in cells floor(q - 0.5) + {0, 1}³ of
//                      smoothstep(clamp((radius + edge - |q - centre|) / (2 edge), 0, 1))
#pragma once

#include <array>
#include <cmath>
#include <cstdint>

#include "dslr/simd.h"

namespace rigc::scene::speckle {

inline constexpr float kPrime = 289;
inline constexpr int kDotsPerCell = 2;
inline constexpr std::array<float, kDotsPerCell> kDotStarts = {1, 145};
inline constexpr float kRadiusMin = 0.28f;
inline constexpr float kRadiusSpan = 0.14f;
// Half-width of a dot's soft edge (each renderer's pixel filter on top).
inline constexpr float kEdge = 0.06f;
// Mean darkness over the surface, what the pattern fades to when too fine to resolve
// (Studio.ResolvedPatternsAverageToTheirFadedValue measures it).
inline constexpr float kMeanDarkness = 0.33f;

// The seed as the hash's offset, in [0, 289).
inline float seed_offset(std::uint32_t seed) {
  return static_cast<float>(seed % 289u);
}

// The hash's steps on eight lanes, exact in float: x mod 289 (x an integer, |x| < 2^24) and
// perm(v) (v an integer in [0, 578)).
simd::F32x8 mod289(simd::F32x8 x);
simd::F32x8 perm(simd::F32x8 v);

// The darkness in [0, 1] at eight points q (cells), each lane with its own edge half-width
// (kEdge for the pattern itself; a dot's edge is narrowed where it would reach past half a cell).
simd::F32x8 darkness8(simd::F32x8 qx, simd::F32x8 qy, simd::F32x8 qz, float seed_offset,
                      simd::F32x8 edge);

// The same at one point, in double precision and plain scalar code: the definition above read
// literally, for tests of darkness8 and of the backends' transcriptions.
double darkness_reference(double qx, double qy, double qz, double seed_offset, double edge);

// Eight pixels' footprints on the surface, in cells: pixel k covers q + s dx + t dy, s and t in
// [-1/2, 1/2], at lane k of each vector.
struct Footprints8 {
  simd::F32x8 qx, qy, qz, dxx, dxy, dxz, dyx, dyy, dyz;
};

// The dots whose soft edges reach into a footprint: centres (cells), radii and edge half-widths.
struct CrossingDots {
  static constexpr int kMost = 8;
  int count = 0;
  std::array<float, kMost> x, y, z, radius, edge;
};

// The dots over each of eight footprints (at edge kEdge), gathered once a pixel for its box
// filter: bit k of the result is set where a dot covers all of pixel k (its darkness is 1);
// otherwise crossing[k] holds the dots whose soft edges reach into it (none: its darkness is 0),
// and its darkness at any point of it is theirs alone (darkness_of8). More than
// CrossingDots::kMost such dots leave crossing[k].count at -1 (sample the pattern itself).
unsigned dots_over8(const Footprints8& pixels, float seed_offset,
                    std::array<CrossingDots, 8>& crossing);

// The darkness at eight points where only `dots` can reach: the darkest of them.
simd::F32x8 darkness_of8(simd::F32x8 qx, simd::F32x8 qy, simd::F32x8 qz, const CrossingDots& dots);

}  // namespace rigc::scene::speckle

// The `noise` pattern on the speckle's hash: three octaves of value noise, one function of the
// object-frame point that every renderer evaluates alike (backends/ write it from these
// constants).
//
//   lattice(c, s) = hash(c) / 288, with the speckle's hash at seed offset s
//   value(q, s)   = lattice at the 8 corners of q's unit cell, blended trilinearly with weights
//                   smoothstep(q - floor(q))
//   darkness      = sum over octaves k of kAmplitudes[k] · value(kFrequencies[k] · q, s_k) / 0.875,
//                   s_k = seed_offset(seed + k)
namespace rigc::scene::noise {

inline constexpr int kOctaves = 3;
inline constexpr std::array<float, kOctaves> kFrequencies = {1.0f, 2.1f, 4.41f};
inline constexpr std::array<float, kOctaves> kAmplitudes = {0.5f, 0.25f, 0.125f};
inline constexpr float kAmplitudeSum = 0.875f;
// The lattice values are uniform over {0, 1/288, ..., 1}: the pattern averages a half.
inline constexpr float kMeanDarkness = 0.5f;

// The darkness in [0, 1] at eight points q (cells) for the pattern's seed.
simd::F32x8 darkness8(simd::F32x8 qx, simd::F32x8 qy, simd::F32x8 qz, std::uint32_t seed);

// The same at one point in double precision, the definition read literally (for tests).
double darkness_reference(double qx, double qy, double qz, std::uint32_t seed);

}  // namespace rigc::scene::noise
