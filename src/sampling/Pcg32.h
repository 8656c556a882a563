// PCG32 (O'Neill 2014): a small, fast generator with independent streams per pixel.
#pragma once

#include "core/Common.h"

namespace envgi {

// 32 random bits to a float in [0,1): the top 24 become the mantissa, so 1.0 never comes out.
ENVGI_INLINE float bitsToFloat01(uint32_t v) { return float(v >> 8) * 0x1p-24f; }

struct Pcg32 {
  uint64_t state = 0x853c49e6748fea9bULL;
  uint64_t inc = 0xda3e39cb94b95bdbULL;

  Pcg32() = default;
  ENVGI_HD Pcg32(uint64_t seed, uint64_t stream = 1) { setSeed(seed, stream); }

  ENVGI_HD void setSeed(uint64_t seed, uint64_t stream) {
    state = 0u;
    inc = (stream << 1u) | 1u;
    nextUInt();
    state += seed;
    nextUInt();
  }
  ENVGI_HD uint32_t nextUInt() {
    uint64_t old = state;
    state = old * 0x5851f42d4c957f2dULL + inc;
    uint32_t xorshifted = uint32_t(((old >> 18u) ^ old) >> 27u);
    uint32_t rot = uint32_t(old >> 59u);
    return (xorshifted >> rot) | (xorshifted << ((~rot + 1u) & 31));
  }
  ENVGI_HD float nextFloat() { return bitsToFloat01(nextUInt()); }
};

// 64-bit mixing hash (splitmix64 finaliser), for deriving seeds from pixel and dimension.
ENVGI_INLINE uint64_t mixBits(uint64_t v) {
  v ^= v >> 31;
  v *= 0x7fb5d329728ea185ULL;
  v ^= v >> 27;
  v *= 0x81dadef4bc2dd44dULL;
  v ^= v >> 33;
  return v;
}

ENVGI_INLINE uint64_t hashCombine(uint64_t a, uint64_t b) { return mixBits(a ^ (b + 0x9e3779b97f4a7c15ULL + (a << 6) + (a >> 2))); }

}  // namespace envgi
