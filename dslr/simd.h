// Small helpers on GCC's vector extensions: eight or four lanes of float and int32, one AVX (or
// SSE) register where the build targets it, plain lane loops otherwise.
#pragma once

#include <cmath>
#include <cstdint>
#include <cstring>

#if defined(__SSE4_1__) || defined(__AVX__)
#include <immintrin.h>
#endif

namespace rigc::simd {

using F32x8 = float __attribute__((vector_size(32)));
using I32x8 = std::int32_t __attribute__((vector_size(32)));
using U32x8 = std::uint32_t __attribute__((vector_size(32)));
using F32x4 = float __attribute__((vector_size(16)));
using I32x4 = std::int32_t __attribute__((vector_size(16)));

// Whether any lane of a comparison's mask is set.
inline bool any(I32x8 mask) {
#if defined(__AVX__)
  const __m256i bits = reinterpret_cast<__m256i>(mask);
  return !_mm256_testz_si256(bits, bits);
#else
  std::uint64_t words[4];
  std::memcpy(words, &mask, sizeof(words));
  return (words[0] | words[1] | words[2] | words[3]) != 0;
#endif
}

inline bool any(I32x4 mask) {
#if defined(__SSE4_1__)
  const __m128i bits = reinterpret_cast<__m128i>(mask);
  return !_mm_testz_si128(bits, bits);
#else
  std::uint64_t words[2];
  std::memcpy(words, &mask, sizeof(words));
  return (words[0] | words[1]) != 0;
#endif
}

inline F32x8 sqrt(F32x8 x) {
#if defined(__AVX__)
  return reinterpret_cast<F32x8>(_mm256_sqrt_ps(reinterpret_cast<__m256>(x)));
#else
  for (int k = 0; k < 8; ++k) x[k] = std::sqrt(x[k]);
  return x;
#endif
}

inline F32x8 floor(F32x8 x) {
#if defined(__AVX__)
  return reinterpret_cast<F32x8>(_mm256_floor_ps(reinterpret_cast<__m256>(x)));
#else
  for (int k = 0; k < 8; ++k) x[k] = std::floor(x[k]);
  return x;
#endif
}

// Eight or four floats from p, aligned or not.
inline F32x8 load8(const float* p) {
  F32x8 v;
  std::memcpy(&v, p, sizeof v);
  return v;
}
inline F32x4 load4(const float* p) {
  F32x4 v;
  std::memcpy(&v, p, sizeof v);
  return v;
}

// x[index[k]] in each lane k (index in 0..7).
inline F32x8 permute(F32x8 x, I32x8 index) {
#if defined(__AVX2__)
  return reinterpret_cast<F32x8>(
      _mm256_permutevar8x32_ps(reinterpret_cast<__m256>(x), reinterpret_cast<__m256i>(index)));
#else
  F32x8 out;
  for (int k = 0; k < 8; ++k) out[k] = x[index[k] & 7];
  return out;
#endif
}

// base[index[k]] in each lane k.
inline F32x8 gather(const float* base, I32x8 index) {
#if defined(__AVX2__)
  return reinterpret_cast<F32x8>(_mm256_i32gather_ps(base, reinterpret_cast<__m256i>(index), 4));
#else
  F32x8 out;
  for (int k = 0; k < 8; ++k) out[k] = base[index[k]];
  return out;
#endif
}

// How many lanes of a comparison's mask are set.
inline int count(I32x8 mask) {
#if defined(__AVX__)
  return __builtin_popcount(_mm256_movemask_ps(reinterpret_cast<__m256>(mask)));
#else
  int n = 0;
  for (int k = 0; k < 8; ++k) n += mask[k] != 0;
  return n;
#endif
}

// The sum of the eight lanes.
inline float sum(F32x8 x) {
  float total = 0;
  for (int k = 0; k < 8; ++k) total += x[k];
  return total;
}

}  // namespace rigc::simd
