#include "scene/speckle.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

namespace rigc::scene::speckle {
namespace {

// darkness8 (float, SIMD) is the definition read in double: the hash is exact in both, so the
// dots are the same and only rounding separates them.
TEST(Speckle, SimdMatchesTheReferenceDefinition) {
  std::mt19937 random(3);
  std::uniform_real_distribution<float> coordinate(-300.0f, 300.0f);
  double worst = 0;
  int dark = 0;
  for (int batch = 0; batch < 2000; ++batch) {
    simd::F32x8 qx, qy, qz;
    for (int k = 0; k < 8; ++k) {
      qx[k] = coordinate(random);
      qy[k] = coordinate(random);
      qz[k] = coordinate(random);
    }
    const simd::F32x8 edge = simd::F32x8{} + kEdge;
    const simd::F32x8 d = darkness8(qx, qy, qz, seed_offset(7), edge);
    for (int k = 0; k < 8; ++k) {
      const double want = darkness_reference(qx[k], qy[k], qz[k], seed_offset(7), kEdge);
      worst = std::max(worst, std::abs(d[k] - want));
      dark += want > 0.5;
    }
  }
  EXPECT_LT(worst, 1e-3);
  // About a third of the surface is dark.
  EXPECT_GT(dark, 0.2 * 16000);
  EXPECT_LT(dark, 0.5 * 16000);
}

// Eight points sharing their 2 x 2 x 2 cells (a pixel's filter samples) take a path that hashes
// the cells once: it gives the general path's darkness, bit for bit (the renderer's two ways of
// batching a pixel's samples must shade alike).
TEST(Speckle, PointsInOneBlockMatchTheGeneralPath) {
  std::mt19937 random(5);
  std::uniform_real_distribution<float> corner(-300.0f, 300.0f), offset(0.5f, 1.5f);
  const simd::F32x8 edge = simd::F32x8{} + kEdge;
  int compared = 0;
  for (int batch = 0; batch < 500; ++batch) {
    const float bx = std::floor(corner(random)), by = std::floor(corner(random)),
                bz = std::floor(corner(random));
    simd::F32x8 qx, qy, qz;
    for (int k = 0; k < 8; ++k) {
      qx[k] = bx + offset(random);
      qy[k] = by + offset(random);
      qz[k] = bz + offset(random);
    }
    const simd::F32x8 one_block = darkness8(qx, qy, qz, seed_offset(7), edge);
    // Lane 7 moved three cells away: the general path for the other seven.
    simd::F32x8 mixed_x = qx;
    mixed_x[7] += 3;
    const simd::F32x8 general = darkness8(mixed_x, qy, qz, seed_offset(7), edge);
    for (int k = 0; k < 7; ++k) {
      ASSERT_EQ(one_block[k], general[k]) << "batch " << batch << " lane " << k;
      ++compared;
    }
    const double want = darkness_reference(qx[7], qy[7], qz[7], seed_offset(7), kEdge);
    EXPECT_NEAR(one_block[7], want, 1e-3);
  }
  EXPECT_EQ(compared, 3500);
}

// No square cells: the pattern changes as much along a cell's edge as along its diagonal.
TEST(Speckle, IsotropicAcrossCells) {
  std::mt19937 random(11);
  std::uniform_real_distribution<double> coordinate(-40.0, 40.0);
  const double step = 0.3, diagonal = step / std::sqrt(3.0);
  double along_axis = 0, along_diagonal = 0, mean = 0;
  constexpr int kPoints = 40000;
  for (int i = 0; i < kPoints; ++i) {
    const double x = coordinate(random), y = coordinate(random), z = coordinate(random);
    const double here = darkness_reference(x, y, z, 5, kEdge);
    mean += here;
    along_axis += std::abs(darkness_reference(x + step, y, z, 5, kEdge) - here);
    along_diagonal +=
        std::abs(darkness_reference(x + diagonal, y + diagonal, z + diagonal, 5, kEdge) - here);
  }
  EXPECT_NEAR(along_diagonal / along_axis, 1.0, 0.05);
  EXPECT_NEAR(mean / kPoints, kMeanDarkness, 0.02);
}

// The dots gathered over a pixel are all that darken it: at any point of the pixel the darkness
// from them alone is the pattern's, a pixel called covered is dark all over, and one with no
// dots is light all over.
TEST(Speckle, DotsOverAPixelAreAllThatDarkenIt) {
  std::mt19937 random(9);
  std::uniform_real_distribution<float> coordinate(-60.0f, 60.0f), side(-0.35f, 0.35f),
      offset(-0.5f, 0.5f), spread(0.0f, 0.4f);
  int covered = 0, light = 0, crossed = 0;
  for (int batch = 0; batch < 400; ++batch) {
    Footprints8 pixels;
    // Half the batches close together (one surface), half scattered.
    const float x = coordinate(random), y = coordinate(random), z = coordinate(random);
    const bool close = batch % 2 == 0;
    for (int k = 0; k < 8; ++k) {
      pixels.qx[k] = close ? x + spread(random) : coordinate(random);
      pixels.qy[k] = close ? y + spread(random) : coordinate(random);
      pixels.qz[k] = close ? z + spread(random) : coordinate(random);
      for (simd::F32x8* v :
           {&pixels.dxx, &pixels.dxy, &pixels.dxz, &pixels.dyx, &pixels.dyy, &pixels.dyz}) {
        (*v)[k] = side(random);
      }
    }
    std::array<CrossingDots, 8> crossing;
    const unsigned full = dots_over8(pixels, seed_offset(5), crossing);
    for (int k = 0; k < 8; ++k) {
      ASSERT_GE(crossing[k].count, 0) << "more dots than kMost over a pixel of this size";
      simd::F32x8 qx, qy, qz;
      for (int m = 0; m < 8; ++m) {
        const float s = offset(random), t = offset(random);
        qx[m] = pixels.qx[k] + s * pixels.dxx[k] + t * pixels.dyx[k];
        qy[m] = pixels.qy[k] + s * pixels.dxy[k] + t * pixels.dyy[k];
        qz[m] = pixels.qz[k] + s * pixels.dxz[k] + t * pixels.dyz[k];
      }
      const simd::F32x8 want = darkness8(qx, qy, qz, seed_offset(5), simd::F32x8{} + kEdge);
      const simd::F32x8 from_dots = darkness_of8(qx, qy, qz, crossing[k]);
      for (int m = 0; m < 8; ++m) {
        if (full >> k & 1u) {
          EXPECT_EQ(want[m], 1.0f);
        } else {
          EXPECT_NEAR(from_dots[m], want[m], 1e-4);  // rounding: the centres are summed once
        }
      }
      covered += (full >> k) & 1u;
      light += !((full >> k) & 1u) && crossing[k].count == 0;
      crossed += !((full >> k) & 1u) && crossing[k].count > 0;
    }
  }
  // Every kind of pixel was met.
  EXPECT_GT(covered, 10);
  EXPECT_GT(light, 100);
  EXPECT_GT(crossed, 100);
}

}  // namespace
}  // namespace rigc::scene::speckle

namespace rigc::scene::noise {
namespace {

// The noise pattern's SIMD form is its definition read in double (speckle.h), with smooth
// values over [0, 1] averaging a half.
TEST(Speckle, NoiseSimdMatchesTheReferenceDefinition) {
  std::mt19937 random(5);
  std::uniform_real_distribution<float> coordinate(-200.0f, 200.0f);
  double worst = 0, mean = 0, lowest = 1, highest = 0;
  constexpr int kBatches = 2000;
  for (int batch = 0; batch < kBatches; ++batch) {
    simd::F32x8 qx, qy, qz;
    for (int k = 0; k < 8; ++k) {
      qx[k] = coordinate(random);
      qy[k] = coordinate(random);
      qz[k] = coordinate(random);
    }
    const simd::F32x8 d = darkness8(qx, qy, qz, 11);
    for (int k = 0; k < 8; ++k) {
      const double want = darkness_reference(qx[k], qy[k], qz[k], 11);
      worst = std::max(worst, std::abs(d[k] - want));
      mean += want / (8 * kBatches);
      lowest = std::min(lowest, want);
      highest = std::max(highest, want);
    }
  }
  EXPECT_LT(worst, 1e-3);
  EXPECT_NEAR(mean, kMeanDarkness, 0.02);
  EXPECT_GE(lowest, 0);
  EXPECT_LE(highest, 1);
  EXPECT_GT(highest - lowest, 0.6);
}

}  // namespace
}  // namespace rigc::scene::noise
