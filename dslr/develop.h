// Development of the sensor signal into an image file's pixels: white balance, tone curve, sRGB.
#pragma once

#include <algorithm>
#include <array>
#include <cstdint>
#include <vector>

#include "ir/ir.h"

namespace rigc::dslr {

// Linear sRGB of a blackbody at `kelvin`, normalised to luminance 1 (the same function the
// compiler uses for light colours, so a light of T kelvin is neutral under white balance T).
ir::Vec3 blackbody_rgb(double kelvin);

// Per-channel gains that make a neutral surface neutral, preserving luminance.
//  - kKelvin: 1 / blackbody_rgb(white_balance_k).
//  - kAuto: gray world: the mean colour of the masked pixels (the object; all pixels when the
//    mask is empty or nearly so), ignoring clipped ones, is made grey. Gains are kept in 1/8..8.
std::array<double, 3> white_balance_gains(const ir::Camera& camera,
                                          const std::vector<float>& linear,
                                          const std::vector<std::uint8_t>& mask);

// The sRGB transfer function (IEC 61966-2-1) on [0, 1].
double srgb_oetf(double linear);

// Tone curve and encoding: the white-balanced signal is clipped to [0, 1] (highlights clip as
// on the sensor; no filmic shoulder, so the response stays exactly invertible) and encoded with
// the sRGB transfer function to `bits` (8 or 16). A metered average (v = 12.5·q/78 ≈ 0.104)
// lands at code 91/255, where camera JPEGs typically lift a metered grey to ~118 with their tone
// curve: previews look about 3/4 stop darker than in-camera JPEGs, but stay linear to invert.
std::vector<std::uint16_t> encode_srgb(const std::vector<float>& linear,
                                       const std::array<double, 3>& gains, int bits);

// encode_srgb for one value of colour channel c (0, 1, 2), for a stage that fuses the encoding
// into its own pass: the same table and gains, so the same codes.
struct SrgbEncoding {
  // table[0 .. last], and one entry more that may be read but is never used.
  const std::uint16_t* table = nullptr;
  float last = 0;                      // the table's last index
  std::array<float, 3> scaled_gain{};  // gain x last, per channel
  std::uint16_t operator()(float value, int channel) const {
    // Written so that NaN lands on 0, as in the fused vector pass.
    float x = value * scaled_gain[channel];
    x = x > 0 ? x : 0.0f;
    x = x < last ? x : last;
    return table[static_cast<std::size_t>(x + 0.5f)];
  }
};
SrgbEncoding srgb_encoding(const std::array<double, 3>& gains, int bits);

}  // namespace rigc::dslr
