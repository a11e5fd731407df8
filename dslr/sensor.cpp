#include "dslr/sensor.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <numbers>

namespace rigc::dslr {

double electrons_at_clipping(const ir::SensorNoise& noise, double iso) {
  return noise.full_well_e * noise.base_iso / iso;
}

double read_noise_electrons(const ir::SensorNoise& noise, double iso) {
  constexpr double kHighIso = 6400;
  if (noise.read_noise_e <= 0 || noise.read_noise_high_iso_e <= 0 || noise.base_iso >= kHighIso) {
    return std::max(0.0, noise.read_noise_e);
  }
  const double t =
      std::clamp(std::log(iso / noise.base_iso) / std::log(kHighIso / noise.base_iso), 0.0, 1.0);
  return std::exp((1 - t) * std::log(noise.read_noise_e) +
                  t * std::log(noise.read_noise_high_iso_e));
}

int black_level_dn(int adc_bits) {
  return 1 << std::max(0, adc_bits - 3);
}

namespace {

std::uint64_t splitmix64(std::uint64_t x) {
  x += 0x9E3779B97F4A7C15ull;
  x = (x ^ (x >> 30)) * 0xBF58476D1CE4E5B9ull;
  x = (x ^ (x >> 27)) * 0x94D049BB133111EBull;
  return x ^ (x >> 31);
}

// Acklam's rational approximation of the inverse normal CDF, refined by one Newton step.
double inverse_normal_cdf(double p) {
  static constexpr double a[] = {-3.969683028665376e+01, 2.209460984245205e+02,
                                 -2.759285104469687e+02, 1.383577518672690e+02,
                                 -3.066479806614716e+01, 2.506628277459239e+00};
  static constexpr double b[] = {-5.447609879822406e+01, 1.615858368580409e+02,
                                 -1.556989798598866e+02, 6.680131188771972e+01,
                                 -1.328068155288572e+01};
  static constexpr double c[] = {-7.784894002430293e-03, -3.223964580411365e-01,
                                 -2.400758277161838e+00, -2.549732539343734e+00,
                                 4.374664141464968e+00,  2.938163982698783e+00};
  static constexpr double d[] = {7.784695709041462e-03, 3.224671290700398e-01,
                                 2.445134137142996e+00, 3.754408661907416e+00};
  double x;
  if (p < 0.02425) {
    const double q = std::sqrt(-2 * std::log(p));
    x = (((((c[0] * q + c[1]) * q + c[2]) * q + c[3]) * q + c[4]) * q + c[5]) /
        ((((d[0] * q + d[1]) * q + d[2]) * q + d[3]) * q + 1);
  } else if (p <= 1 - 0.02425) {
    const double q = p - 0.5, r = q * q;
    x = (((((a[0] * r + a[1]) * r + a[2]) * r + a[3]) * r + a[4]) * r + a[5]) * q /
        (((((b[0] * r + b[1]) * r + b[2]) * r + b[3]) * r + b[4]) * r + 1);
  } else {
    const double q = std::sqrt(-2 * std::log(1 - p));
    x = -(((((c[0] * q + c[1]) * q + c[2]) * q + c[3]) * q + c[4]) * q + c[5]) /
        ((((d[0] * q + d[1]) * q + d[2]) * q + d[3]) * q + 1);
  }
  const double e = 0.5 * std::erfc(-x / std::sqrt(2.0)) - p;
  return x - e * std::sqrt(2 * std::numbers::pi) * std::exp(0.5 * x * x);
}

const std::array<float, 65536>& normal_table() {
  static const std::array<float, 65536> table = [] {
    std::array<float, 65536> t{};
    for (int k = 0; k < 65536; ++k)
      t[k] = static_cast<float>(inverse_normal_cdf((k + 0.5) / 65536));
    return t;
  }();
  return table;
}

// Poisson sample by inversion from a uniform in [0, 1); for small means only.
double poisson_small(double mean, double u) {
  double p = std::exp(-mean), cumulative = p;
  int k = 0;
  while (u > cumulative && k < 200) {
    ++k;
    p *= mean / k;
    cumulative += p;
  }
  return k;
}

std::uint64_t stream_key(std::uint64_t seed, std::uint64_t stream) {
  return splitmix64(seed ^ splitmix64(stream));
}

enum Stream : std::uint64_t { kPrnuDsnu = 1, kReadNormal = 2, kShotNormal = 3, kShotUniform = 4 };

// Below this mean the Gaussian approximation of the Poisson law is visibly skewed.
constexpr double kExactPoissonBelow = 30;

}  // namespace

std::uint64_t hash64(std::uint64_t seed, std::uint64_t stream, std::uint64_t index) {
  return splitmix64(index ^ stream_key(seed, stream));
}

float normal_from_bits(std::uint32_t bits16) {
  return normal_table()[bits16 & 0xFFFF];
}

void apply_sensor(const ir::Camera& camera, int width, int height, std::vector<float>& signal,
                  std::uint64_t seed, int shot_index) {
  const std::size_t pixels = static_cast<std::size_t>(width) * height;
  if (!camera.effects.noise) {
    for (float& v : signal) v = std::clamp(v, 0.0f, 1.0f);
    return;
  }
  const ir::SensorNoise& model = camera.noise;
  const double fwc = electrons_at_clipping(model, camera.iso);
  const int bits = std::clamp(model.adc_bits, 1, 24);
  const double dn_max = std::ldexp(1.0, bits) - 1;
  // Single precision is plenty: below 2^17 electrons it resolves 0.01 e⁻.
  const float fwc_f = static_cast<float>(fwc), prnu_f = static_cast<float>(model.prnu);
  const float read_f = static_cast<float>(read_noise_electrons(model, camera.iso));
  const float dsnu_f = static_cast<float>(model.dsnu_e);
  const float dark_f =
      static_cast<float>(std::max(0.0, model.dark_current_e_per_s * camera.shutter_s));
  const float dn_per_e = static_cast<float>(dn_max / fwc), per_dn = static_cast<float>(1 / dn_max);
  const float dn_low = static_cast<float>(-black_level_dn(bits)),
              dn_high = static_cast<float>(dn_max);
  const std::uint64_t fixed_seed = splitmix64(seed);
  const std::uint64_t shot_seed = splitmix64(seed ^ splitmix64(0x5A07ull + shot_index));
  const auto& normal = normal_table();
  const std::uint64_t fixed_key = stream_key(fixed_seed, kPrnuDsnu);
  const std::uint64_t read_key = stream_key(shot_seed, kReadNormal);
  const std::uint64_t shot_key = stream_key(shot_seed, kShotNormal);
  const std::uint64_t uniform_key = stream_key(shot_seed, kShotUniform);

  tbb::parallel_for(
      tbb::blocked_range<std::size_t>(0, pixels, 4096),
      [&](const tbb::blocked_range<std::size_t>& range) {
        for (std::size_t p = range.begin(); p < range.end(); ++p) {
          // Each hash gives four 16-bit normals: PRNU x3 and DSNU x3 take two.
          const std::uint64_t fixed_a = splitmix64((2 * p) ^ fixed_key);
          const std::uint64_t fixed_b = splitmix64((2 * p + 1) ^ fixed_key);
          const std::uint64_t read_bits = splitmix64(p ^ read_key);
          const std::uint64_t shot_bits = splitmix64(p ^ shot_key);
          for (int c = 0; c < 3; ++c) {
            float& v = signal[3 * p + c];
            const float prnu = normal[(fixed_a >> (16 * c)) & 0xFFFF];
            const float dsnu =
                c == 0 ? normal[fixed_a >> 48] : normal[(fixed_b >> (16 * c)) & 0xFFFF];
            const float mean = std::max(0.0f, v * fwc_f * (1 + prnu_f * prnu)) + dark_f;
            float electrons;
            if (mean < kExactPoissonBelow) {
              const std::uint64_t u = splitmix64((3 * p + c) ^ uniform_key);
              electrons =
                  static_cast<float>(poisson_small(mean, static_cast<double>(u >> 11) * 0x1.0p-53));
            } else {
              electrons = mean + std::sqrt(mean) * normal[(shot_bits >> (16 * c)) & 0xFFFF];
            }
            electrons += read_f * normal[(read_bits >> (16 * c)) & 0xFFFF] + dsnu_f * dsnu;
            v = std::clamp(std::floor(electrons * dn_per_e + 0.5f), dn_low, dn_high) * per_dn;
          }
        }
      });
}

}  // namespace rigc::dslr
