// Integer hashing for deterministic noise (procedural shapes, sensor noise).
#pragma once

#include <cstdint>

namespace rigc {

// lowbias32 (Chris Wellons): a 32-bit integer finaliser with good avalanche. T is std::uint32_t
// or a GCC vector of them (every lane hashed alike).
template <typename T>
inline T lowbias32(T x) {
  x ^= x >> 16;
  x *= 0x7feb352dU;
  x ^= x >> 15;
  x *= 0x846ca68bU;
  x ^= x >> 16;
  return x;
}

}  // namespace rigc
