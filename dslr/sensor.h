// The sensor: photon shot noise, dark current, read noise, fixed-pattern noise, clipping and the
// ADC, in the order ISETCam simulates them (docs/camera-model.md).
#pragma once

#include <cstdint>
#include <vector>

#include "dslr/develop.h"
#include "dslr/image_view.h"
#include "ir/ir.h"

namespace rigc::dslr {

// Electrons at clipping at an ISO: full_well_e · base_iso / iso.
double electrons_at_clipping(const ir::SensorNoise& noise, double iso);

// Read noise (electrons) at an ISO: a power law through read_noise_e at the base ISO and
// read_noise_high_iso_e at ISO 6400 (straight in log-ISO/log-electrons), held flat outside.
// An estimate: the end points are estimates for most presets (see SensorNoise::source_note).
double read_noise_electrons(const ir::SensorNoise& noise, double iso);

// Black level of the simulated ADC, in code values: negative noise excursions down to this are
// kept (as in a raw file before black subtraction) so dark regions keep an unbiased mean.
int black_level_dn(int adc_bits);

// Counter-based random numbers: the value for (seed, stream, index) does not depend on the order
// of evaluation, so results are identical with any number of threads.
std::uint64_t hash64(std::uint64_t seed, std::uint64_t stream, std::uint64_t index);
// Standard normal from 16 bits (a table of the inverse CDF at bin centres, |z| <= 4.3).
float normal_from_bits(std::uint32_t bits16);

// Which draw of the sensor's noise: the camera's seed fixes its fixed-pattern noise (PRNU and
// DSNU: the same camera gives the same pattern in every shot), the shot's index varies the
// temporal noise.
struct NoiseDraw {
  std::uint64_t seed = 1;
  int shot_index = 0;
};

// Applies the sensor to a normalised signal (3 per pixel, 1.0 = clipping at this ISO), in place:
//   e = v·electrons_at_clipping; PRNU gain; + dark current·t; Poisson shot noise (exact below
//   12 e⁻; above, one Gaussian for shot and read noise together, with the Poisson law's skew
//   added by a Cornish-Fisher term); + Gaussian read noise; + DSNU offset; quantise to adc_bits
//   with clipping at full scale; back to normalised. PRNU and DSNU are drawn once per camera
//   seed and resolution and kept (one byte each per value).
// Each colour channel is simulated as its own photosite (no Bayer mosaic). With
// camera.effects.noise off the signal is only clipped to [0, 1]. An empty view (view_of a vector
// of the wrong size) is left alone.
void apply_sensor(const ir::Camera& camera, ImageView<float> signal, NoiseDraw draw);

// apply_sensor and then `encode` (white balance and sRGB, see encode_srgb) in one pass, for a
// caller that keeps only the encoded image: the same codes, without writing the noisy signal
// back. `signal` is left as it was.
std::vector<std::uint16_t> apply_sensor_and_encode(const ir::Camera& camera,
                                                   ImageView<const float> signal, NoiseDraw draw,
                                                   const SrgbEncoding& encode);
// The same for an 8-bit encoding (srgb_encoding(gains, 8)): one byte per value. Both return
// nothing for an empty view (view_of a vector of the wrong size), the bytes also for a 16-bit
// encoding.
std::vector<std::uint8_t> apply_sensor_and_encode_bytes(const ir::Camera& camera,
                                                        ImageView<const float> signal,
                                                        NoiseDraw draw, const SrgbEncoding& encode);

}  // namespace rigc::dslr
