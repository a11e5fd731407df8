#include "dslr/develop.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>

#include "dslr/buffer_pool.h"
#include "ir/color.h"

namespace rigc::dslr {

ir::Vec3 blackbody_rgb(double kelvin) {
  return blackbody_linear_srgb(kelvin);
}

std::array<double, 3> white_balance_gains(const ir::Camera& camera,
                                          const std::vector<float>& linear,
                                          const std::vector<std::uint8_t>& mask) {
  if (camera.white_balance == ir::WhiteBalanceMode::kKelvin) {
    const ir::Vec3 white = blackbody_rgb(camera.white_balance_k);
    return {1 / white.x(), 1 / white.y(), 1 / white.z()};
  }
  const std::size_t n = linear.size() / 3;
  std::size_t masked = 0;
  if (mask.size() == n) {
    for (std::uint8_t m : mask) masked += m >= 128;
  }
  // A mask covering almost nothing says little about the light: use the whole frame.
  const bool use_mask = masked > std::max<std::size_t>(16, n / 1000);
  // Fixed blocks summed in order: the gains do not depend on the number of threads.
  constexpr std::size_t kBlock = 1 << 16;
  const std::size_t blocks = (n + kBlock - 1) / kBlock;
  std::vector<std::array<double, 3>> partial(blocks, {0, 0, 0});
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, blocks), [&](const auto& range) {
    for (std::size_t block = range.begin(); block < range.end(); ++block) {
      std::array<double, 3>& s = partial[block];
      for (std::size_t p = block * kBlock; p < std::min(n, (block + 1) * kBlock); ++p) {
        if (use_mask && mask[p] < 128) continue;
        const float* v = &linear[3 * p];
        if (std::max({v[0], v[1], v[2]}) >= 0.98f) continue;  // clipped: its colour is wrong
        for (int c = 0; c < 3; ++c) s[c] += std::max(0.0f, v[c]);
      }
    }
  });
  double sum[3] = {0, 0, 0};
  for (const auto& s : partial) {
    for (int c = 0; c < 3; ++c) sum[c] += s[c];
  }
  const double y = 0.2126 * sum[0] + 0.7152 * sum[1] + 0.0722 * sum[2];
  std::array<double, 3> gains{1, 1, 1};
  if (!(y > 0)) return gains;
  for (int c = 0; c < 3; ++c) {
    gains[c] = sum[c] > 0 ? std::clamp(y / sum[c], 1.0 / 8, 8.0) : 1.0;
  }
  return gains;
}

double srgb_oetf(double linear) {
  linear = std::clamp(linear, 0.0, 1.0);
  return linear <= 0.0031308 ? 12.92 * linear : 1.055 * std::pow(linear, 1 / 2.4) - 0.055;
}

namespace {

// Tables indexed by the linear value: 2^16 entries are exact to 8 bits; 2^20 keep 16-bit output
// within about one code even in the steep segment near black.
const std::vector<std::uint16_t>& srgb_table(int bits) {
  auto build = [](int index_bits, double out_max) {
    const int size = 1 << index_bits;
    // One entry of padding past the end: a vector gather reads entries as 32-bit words.
    std::vector<std::uint16_t> table(size + 1, 0);
    for (int i = 0; i < size; ++i) {
      table[i] =
          static_cast<std::uint16_t>(std::lround(srgb_oetf(double(i) / (size - 1)) * out_max));
    }
    return table;
  };
  // Each built on first use: the 16-bit one is a million pow() calls an 8-bit run never needs.
  if (bits == 8) {
    static const std::vector<std::uint16_t> table8 = build(16, 255);
    return table8;
  }
  static const std::vector<std::uint16_t> table16 = build(20, 65535);
  return table16;
}

}  // namespace

SrgbEncoding srgb_encoding(const std::array<double, 3>& gains, int bits) {
  const std::vector<std::uint16_t>& table = srgb_table(bits);
  SrgbEncoding encoding;
  encoding.table = table.data();
  encoding.last = static_cast<float>(table.size() - 2);  // the last entry is padding
  for (int c = 0; c < 3; ++c) encoding.scaled_gain[c] = float(gains[c] * encoding.last);
  return encoding;
}

std::vector<std::uint16_t> encode_srgb(const std::vector<float>& linear,
                                       const std::array<double, 3>& gains, int bits) {
  const SrgbEncoding encode = srgb_encoding(gains, bits);
  std::vector<std::uint16_t> out = take_words(linear.size());  // every value is written
  const std::size_t n = linear.size() / 3;
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, n, 8192),
                    [&](const tbb::blocked_range<std::size_t>& range) {
                      for (std::size_t p = range.begin(); p < range.end(); ++p) {
                        for (int c = 0; c < 3; ++c) out[3 * p + c] = encode(linear[3 * p + c], c);
                      }
                    });
  return out;
}

}  // namespace rigc::dslr
