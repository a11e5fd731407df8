#include "dslr/sensor.h"

#if defined(__AVX2__)
#include <immintrin.h>
#endif

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>
#include <memory>
#include <mutex>
#include <numbers>

#include "dslr/buffer_pool.h"
#include "dslr/simd.h"
#include "ir/hash.h"

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

std::uint64_t stream_key(std::uint64_t seed, std::uint64_t stream) {
  return splitmix64(seed ^ splitmix64(stream));
}

// Read noise and shot noise share the shot-normal stream (two 16-bit halves of one hash).
enum Stream : std::uint64_t { kPrnuDsnu = 1, kShotNormal = 3, kShotUniform = 4 };

// Below this mean even the skew-corrected Gaussian (see apply_sensor) departs from the Poisson
// law: its discreteness and its mass at zero matter there.
constexpr double kExactPoissonBelow = 12;

constexpr int kNoiseLanes = 8;
using simd::F32x8;
using simd::I32x8;
using simd::U32x8;
constexpr U32x8 kLaneIndex = {0, 1, 2, 3, 4, 5, 6, 7};

// table[index[k]] per lane: the indices are 16-bit, so they read the same as signed.
inline F32x8 lookup(const float* table, U32x8 index) {
  return simd::gather(table, reinterpret_cast<I32x8>(index));
}

// e^-x for 0 <= x < 80 on eight lanes: 2^t split into 2^n (exponent bits) and 2^f (its Taylor
// polynomial of degree 6 on [0, 1), relative error below 2e-5).
inline F32x8 exp_negative8(F32x8 x) {
  const F32x8 t = x * -1.44269504f;  // -x·log2(e), in (-116, 0]
  const F32x8 n = simd::floor(t);
  const F32x8 f = t - n;
  F32x8 poly = F32x8{} + 1.535336188e-4f;
  poly = poly * f + 1.339887440e-3f;
  poly = poly * f + 9.618437357e-3f;
  poly = poly * f + 5.550332471e-2f;
  poly = poly * f + 2.402264791e-1f;
  poly = poly * f + 6.931472028e-1f;
  poly = poly * f + 1.0f;
  const I32x8 exponent = (__builtin_convertvector(n, I32x8) + 127) << 23;
  F32x8 scale;
  std::memcpy(&scale, &exponent, sizeof(scale));
  return poly * scale;
}

// The camera's fixed pattern (PRNU and DSNU normals per value) as signed bytes, z·32 (|z| below
// 4): the same in every shot, so it is drawn once per run instead of two table gathers per value
// and shot. One pattern is kept: a run has one camera and one resolution.
constexpr float kPatternStep = 1.0f / 32;
using I8x8 = std::int8_t __attribute__((vector_size(8)));

struct FixedPattern {
  std::uint32_t key = 0;
  std::size_t values = 0;
  std::vector<std::int8_t> prnu, dsnu;  // padded to a multiple of kNoiseLanes
};

// The pattern's byte for each entry of the normal table: z·32 rounded, within ±127. Three bytes
// of padding: a lane reads its byte as the lowest of four (an integer gather has no byte form).
const std::array<std::int8_t, 65536 + 3>& pattern_table() {
  static const std::array<std::int8_t, 65536 + 3> bytes = [] {
    const auto& normal = normal_table();
    std::array<std::int8_t, 65536 + 3> out{};
    for (int k = 0; k < 65536; ++k) {
      const float steps = std::floor(normal[k] * (1 / kPatternStep) + 0.5f);
      out[k] = static_cast<std::int8_t>(std::clamp(steps, -127.0f, 127.0f));
    }
    return out;
  }();
  return bytes;
}

// bytes[index[k]] in each lane k, as eight signed bytes.
inline I8x8 gather_bytes(const std::int8_t* bytes, U32x8 index) {
#if defined(__AVX2__)
  // Four bytes from each lane's index, of which the first (little-endian) is the one. GCC
  // narrows a vector to bytes one lane at a time in general registers: shuffled here instead,
  // each half's four first bytes to its front, then both fronts together.
  const __m256i words = _mm256_i32gather_epi32(reinterpret_cast<const int*>(bytes),
                                               reinterpret_cast<__m256i>(index), 1);
  const __m256i fronts = _mm256_shuffle_epi8(
      words, _mm256_setr_epi8(0, 4, 8, 12, -1, -1, -1, -1, -1, -1, -1, -1, -1, -1, -1, -1, 0, 4, 8,
                              12, -1, -1, -1, -1, -1, -1, -1, -1, -1, -1, -1, -1));
  const __m256i packed =
      _mm256_permutevar8x32_epi32(fronts, _mm256_setr_epi32(0, 4, 0, 0, 0, 0, 0, 0));
  I8x8 out;
  const long long low = _mm_cvtsi128_si64(_mm256_castsi256_si128(packed));
  std::memcpy(&out, &low, sizeof(out));
  return out;
#else
  I8x8 out;
  for (int k = 0; k < 8; ++k) out[k] = bytes[index[k]];
  return out;
#endif
}

std::shared_ptr<const FixedPattern> fixed_pattern(std::uint32_t key, std::size_t values) {
  static std::mutex mutex;
  static std::shared_ptr<const FixedPattern> kept;
  std::lock_guard lock(mutex);
  if (kept && kept->key == key && kept->values == values) return kept;
  kept.reset();  // freed before the new one is drawn
  auto pattern = std::make_shared<FixedPattern>();
  pattern->key = key;
  pattern->values = values;
  const std::size_t groups = (values + kNoiseLanes - 1) / kNoiseLanes;
  resize_frame_buffer(pattern->prnu, groups * kNoiseLanes);
  resize_frame_buffer(pattern->dsnu, groups * kNoiseLanes);
  // The bytes are looked up already rounded (pattern_table) and narrowed by shuffles.
  const std::int8_t* bytes = pattern_table().data();
  // Plain pointers: stores through a byte pointer may alias anything, so the vectors' data
  // pointers would be reloaded for every group.
  std::int8_t* const prnu_out = pattern->prnu.data();
  std::int8_t* const dsnu_out = pattern->dsnu.data();
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, groups, 4096),
                    [&](const tbb::blocked_range<std::size_t>& range) {
                      for (std::size_t group = range.begin(); group < range.end(); ++group) {
                        const std::size_t first = group * kNoiseLanes;
                        const U32x8 index = static_cast<std::uint32_t>(first) + kLaneIndex;
                        const U32x8 bits = lowbias32(index ^ key);
                        const I8x8 prnu = gather_bytes(bytes, bits & 0xFFFF);
                        const I8x8 dsnu = gather_bytes(bytes, bits >> 16);
                        std::memcpy(prnu_out + first, &prnu, sizeof(prnu));
                        std::memcpy(dsnu_out + first, &dsnu, sizeof(dsnu));
                      }
                    });
  kept = std::move(pattern);
  return kept;
}

inline F32x8 load_pattern(const std::int8_t* p) {
#if defined(__AVX2__)
  // GCC lowers the byte-to-float conversion below to eight scalar conversions.
  const __m256 z = _mm256_cvtepi32_ps(
      _mm256_cvtepi8_epi32(_mm_loadl_epi64(reinterpret_cast<const __m128i*>(p))));
  F32x8 out;
  std::memcpy(&out, &z, sizeof(out));
  return out * kPatternStep;
#else
  I8x8 bytes;
  std::memcpy(&bytes, p, sizeof(bytes));
  return __builtin_convertvector(bytes, F32x8) * kPatternStep;
#endif
}

}  // namespace

std::uint64_t hash64(std::uint64_t seed, std::uint64_t stream, std::uint64_t index) {
  return splitmix64(index ^ stream_key(seed, stream));
}

float normal_from_bits(std::uint32_t bits16) {
  return normal_table()[bits16 & 0xFFFF];
}

namespace {

// fn(first, count) for each group of up to kNoiseLanes values [first, first + count) of
// [0, values), in parallel; first is a multiple of kNoiseLanes.
template <typename Fn>
void for_each_group(std::size_t values, const Fn& fn) {
  tbb::parallel_for(
      tbb::blocked_range<std::size_t>(0, (values + kNoiseLanes - 1) / kNoiseLanes, 1024),
      [&](const tbb::blocked_range<std::size_t>& range) {
        // A local copy of fn (its captures by value): byte stores may alias any memory, so
        // captures read through a reference would be loaded again after every group's store.
        const Fn body = fn;
        for (std::size_t group = range.begin(); group < range.end(); ++group) {
          const std::size_t first = group * kNoiseLanes;
          body(first, std::min<std::size_t>(kNoiseLanes, values - first));
        }
      });
}

// sensor_pass with the noise off: the signal only clipped to [0, 1].
template <typename Store>
void clipping_pass(std::size_t values, const float* signal, const Store& store) {
  for_each_group(values, [=](std::size_t first, std::size_t count) {
    F32x8 x = {};
    std::memcpy(&x, signal + first, count * sizeof(float));
    const F32x8 zero = {}, one = zero + 1;
    x = x < zero ? zero : x;
    x = x > one ? one : x;
    store(first, count, x);
  });
}

// The sensor over `signal` (3 values per pixel), eight values per step: store(first, count, out)
// receives values [first, first + count) as the ADC leaves them, normalised (first is a multiple
// of eight). The store may write over the signal it came from.
template <typename Store>
void sensor_pass(const ir::Camera& camera, ImageView<const float> image, NoiseDraw draw,
                 const Store& store) {
  const float* signal = image.values;
  const std::uint64_t seed = draw.seed;
  const int shot_index = draw.shot_index;
  const std::size_t pixels = image.pixels();
  const std::size_t values = 3 * pixels;
  if (!camera.effects.noise) {
    clipping_pass(values, signal, store);
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
  const std::uint64_t shot_key = stream_key(shot_seed, kShotNormal);
  const std::uint64_t uniform_key = stream_key(shot_seed, kShotUniform);

  // Per value (pixel p, channel c: value 3p + c): PRNU and DSNU from the camera's fixed pattern,
  // and one normal from the shot's stream for shot and read noise together: the sum of two
  // independent normals of variances mean and read² is one normal of variance mean + read².
  // A 32-bit hash of the value's index gives the table index, and eight values go through
  // together (one 8-lane register).
  const std::uint32_t fixed_key32 = static_cast<std::uint32_t>(fixed_key ^ (fixed_key >> 32));
  const std::uint32_t shot_key32 = static_cast<std::uint32_t>(shot_key ^ (shot_key >> 32));
  const float* table = normal.data();
  const std::shared_ptr<const FixedPattern> pattern = fixed_pattern(fixed_key32, values);
  const std::int8_t* prnu_pattern = pattern->prnu.data();
  const std::int8_t* dsnu_pattern = pattern->dsnu.data();
  const float read_variance = read_f * read_f;
  // Below kExactPoissonBelow electrons the Gaussian stands in badly: those values take an
  // exact Poisson draw.
  const std::uint32_t uniform_key32 = static_cast<std::uint32_t>(uniform_key ^ (uniform_key >> 32));
  for_each_group(values, [=](std::size_t first, std::size_t count) {
    const U32x8 index = static_cast<std::uint32_t>(first) + kLaneIndex;
    const U32x8 shot_bits = lowbias32(index ^ shot_key32);
    const F32x8 prnu = load_pattern(prnu_pattern + first);
    const F32x8 dsnu = load_pattern(dsnu_pattern + first);
    const F32x8 temporal = lookup(table, shot_bits & 0xFFFF);
    const float* v = signal + first;
    F32x8 x = {};
    if (count == kNoiseLanes) {
      std::memcpy(&x, v, sizeof(x));
    } else {
      std::memcpy(&x, v, count * sizeof(float));
    }
    const F32x8 zero = {};
    F32x8 mean = x * fwc_f * (1 + prnu_f * prnu);
    mean = (mean > zero ? mean : zero) + dark_f;
    const I32x8 small = mean < static_cast<float>(kExactPoissonBelow);
    // Cornish-Fisher: the Poisson part's third cumulant (= mean) gives the sum a skew,
    // mean / (6 s²)·(z² - 1) with s² = mean + read², which a plain Gaussian lacks.
    const F32x8 variance = mean + read_variance;
    const F32x8 skew = mean / (6 * variance);
    F32x8 electrons = mean + simd::sqrt(variance) * temporal + skew * (temporal * temporal - 1);
    if (simd::any(small)) {
      // Dark values (a green screen's red channel): an exact Poisson draw by inversion,
      // all lanes at once, from a second hash as the uniform, plus the read noise.
      const U32x8 uniform_bits = lowbias32(index ^ uniform_key32);
      const F32x8 u = __builtin_convertvector(uniform_bits >> 8, F32x8) * 0x1.0p-24f;
      const F32x8 clamped_mean = small ? mean : zero;
      F32x8 p = exp_negative8(clamped_mean), cumulative = p, k = zero;
      I32x8 going = small & (u > cumulative);
      for (int step = 1; step <= 200 && simd::any(going); ++step) {
        p = p * clamped_mean * (1.0f / static_cast<float>(step));
        cumulative += p;
        k = going ? k + 1.0f : k;
        going = going & (u > cumulative);
      }
      electrons = small ? k + read_f * temporal : electrons;
    }
    electrons += dsnu_f * dsnu;
    F32x8 dn = simd::floor(electrons * dn_per_e + 0.5f);
    dn = dn < dn_low ? F32x8{} + dn_low : dn;
    dn = dn > dn_high ? F32x8{} + dn_high : dn;
    store(first, count, dn * per_dn);
  });
}

}  // namespace

void apply_sensor(const ir::Camera& camera, ImageView<float> signal, NoiseDraw draw) {
  if (signal.empty() || signal.channels != 3) return;
  float* values = signal.values;
  sensor_pass(camera, ImageView<const float>{values, signal.width, signal.height}, draw,
              [values](std::size_t first, std::size_t count, F32x8 out) {
                if (count == kNoiseLanes) {
                  std::memcpy(values + first, &out, sizeof(out));
                } else {
                  std::memcpy(values + first, &out, count * sizeof(float));
                }
              });
}

namespace {

// apply_sensor_and_encode for codes of type Code (std::uint16_t, or std::uint8_t for 8-bit
// tables).
template <typename Code>
std::vector<Code> sensor_and_encode(const ir::Camera& camera, ImageView<const float> signal,
                                    NoiseDraw draw, const SrgbEncoding& encode) {
  if (signal.empty() || signal.channels != 3) return {};
  // From the pool (a writer hands it back); every value is written.
  std::vector<Code> encoded;
  if constexpr (sizeof(Code) == 1) {
    encoded = take_bytes(signal.size());
  } else {
    encoded = take_words(signal.size());
  }
  Code* codes = encoded.data();
  // Value i is channel i % 3: a group starting at value `first` has the gains of phase first % 3.
  std::array<F32x8, 3> gains;
  for (int phase = 0; phase < 3; ++phase) {
    for (int k = 0; k < kNoiseLanes; ++k) gains[phase][k] = encode.scaled_gain[(phase + k) % 3];
  }
  const std::uint16_t* table = encode.table;
  const float last = encode.last;
  sensor_pass(camera, signal, draw,
              [codes, table, last, gains](std::size_t first, std::size_t count, F32x8 out) {
                // SrgbEncoding's arithmetic, eight values at once.
                const F32x8 zero = {};
                F32x8 x = out * gains[first % 3];
                x = x > zero ? x : zero;
                x = x < last ? x : zero + last;
                const I32x8 index = __builtin_convertvector(x + 0.5f, I32x8);
                if (count < kNoiseLanes) {
                  for (std::size_t k = 0; k < count; ++k) {
                    codes[first + k] = static_cast<Code>(table[index[k]]);
                  }
                  return;
                }
#if defined(__AVX2__)
                // Entries read as 32-bit words at 2-byte steps (the table has a padding entry),
                // the high half dropped, then packed down to the code's width.
                const __m256i words =
                    _mm256_and_si256(_mm256_i32gather_epi32(reinterpret_cast<const int*>(table),
                                                            reinterpret_cast<__m256i>(index), 2),
                                     _mm256_set1_epi32(0xFFFF));
                const __m128i codes16 = _mm_packus_epi32(_mm256_castsi256_si128(words),
                                                         _mm256_extracti128_si256(words, 1));
                if constexpr (sizeof(Code) == 1) {
                  _mm_storel_epi64(reinterpret_cast<__m128i*>(codes + first),
                                   _mm_packus_epi16(codes16, codes16));
                } else {
                  _mm_storeu_si128(reinterpret_cast<__m128i*>(codes + first), codes16);
                }
#else
                for (int k = 0; k < kNoiseLanes; ++k) {
                  codes[first + k] = static_cast<Code>(table[index[k]]);
                }
#endif
              });
  return encoded;
}

}  // namespace

std::vector<std::uint16_t> apply_sensor_and_encode(const ir::Camera& camera,
                                                   ImageView<const float> signal, NoiseDraw draw,
                                                   const SrgbEncoding& encode) {
  return sensor_and_encode<std::uint16_t>(camera, signal, draw, encode);
}

std::vector<std::uint8_t> apply_sensor_and_encode_bytes(const ir::Camera& camera,
                                                        ImageView<const float> signal,
                                                        NoiseDraw draw,
                                                        const SrgbEncoding& encode) {
  // Bytes hold 8-bit codes only: the 8-bit table's index runs to 2^16 - 1.
  if (encode.last != 65535.0f) return {};
  return sensor_and_encode<std::uint8_t>(camera, signal, draw, encode);
}

}  // namespace rigc::dslr
