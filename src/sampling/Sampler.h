// Per-pixel sample sequences: independent (PCG32), stratified (jittered) and Sobol with
// Owen scrambling. Plain data; a sample is addressed by (pixel, index, dimension), so the
// same seed gives the same image whatever the thread count.
#pragma once

#include "sampling/Pcg32.h"
#include "core/Vec.h"

namespace envgi {

enum class SamplerType : int { Independent = 0, Stratified = 1, Sobol = 2 };

ENVGI_INLINE uint32_t reverseBits32(uint32_t v) {
#if defined(__CUDA_ARCH__)
  return __brev(v);
#else
  // A byte swap does the two widest steps of the five in one instruction.
  v = __builtin_bswap32(v);
  v = ((v >> 1) & 0x55555555u) | ((v & 0x55555555u) << 1);
  v = ((v >> 2) & 0x33333333u) | ((v & 0x33333333u) << 2);
  return ((v >> 4) & 0x0F0F0F0Fu) | ((v & 0x0F0F0F0Fu) << 4);
#endif
}

// The first two dimensions of Sobol' (van der Corput and the Pascal-matrix dimension) with
// their bits reversed, the form the scrambler works in: dimension 0 is then the index itself,
// and dimension 1 builds its reversed generator columns directly.
ENVGI_INLINE uint32_t sobolDim0Reversed(uint32_t i) { return i; }
ENVGI_INLINE uint32_t sobolDim1Reversed(uint32_t i) {
  // Column k of the reversed generator has bit j set where C(k, j) is odd, i.e. where j is a
  // subset of k (Lucas), so bit j of the result is the parity of i's bits at supersets of j: a
  // superset-sum transform, one shift-mask step per bit of a bit position, with no branches
  // (the loop over i's bits it replaces mispredicted: 68 -> 87 M draws/s, BM_SamplerDraws/2/64).
  i ^= (i >> 1) & 0x55555555u;
  i ^= (i >> 2) & 0x33333333u;
  i ^= (i >> 4) & 0x0F0F0F0Fu;
  i ^= (i >> 8) & 0x00FF00FFu;
  i ^= (i >> 16) & 0x0000FFFFu;
  return i;
}

// Laine-Karras hash on bit-reversed values: each output bit depends only on the bits below it,
// which, reversed, is nested uniform (Owen) scrambling.
ENVGI_INLINE uint32_t laineKarrasPermutation(uint32_t v, uint32_t seed) {
  v += seed;
  v ^= v * 0x6c50b47cu;
  v ^= v * 0xb82f1e52u;
  v ^= v * 0xc7afe638u;
  v ^= v * 0x8d22f6e6u;
  return v;
}

// Nested uniform (Owen) scrambling of a value handed over with its bits reversed
// (sobolDim*Reversed); the result is in natural bit order.
ENVGI_INLINE uint32_t owenScrambleReversed(uint32_t reversedV, uint32_t seed) {
  return reverseBits32(laineKarrasPermutation(reversedV, seed));
}

// Kensler's hashed permutation: element i of a pseudo-random permutation of [0, n).
ENVGI_INLINE uint32_t permutationElement(uint32_t i, uint32_t l, uint32_t p) {
  uint32_t w = l - 1;
  w |= w >> 1; w |= w >> 2; w |= w >> 4; w |= w >> 8; w |= w >> 16;
  do {
    i ^= p; i *= 0xe170893d; i ^= p >> 16; i ^= (i & w) >> 4; i ^= p >> 8; i *= 0x0929eb3f;
    i ^= p >> 23; i ^= (i & w) >> 1; i *= 1 | p >> 27; i *= 0x6935fa69; i ^= (i & w) >> 11;
    i *= 0x74dcb303; i ^= (i & w) >> 2; i *= 0x9e501cc3; i ^= (i & w) >> 2; i *= 0xc860a3df;
    i &= w; i ^= i >> 5;
  } while (i >= l);
  // A power of two (the usual sample count) needs no division, which would sit on every draw's
  // critical path.
  return (l & (l - 1)) == 0 ? (i + p) & (l - 1) : (i + p) % l;
}

// The power-of-two block of [0, n) that i falls in, with n split into its binary digits from the
// top (n = 96: [0, 64), then [64, 96)). A (0,2)-sequence's aligned power-of-two blocks are nets, so
// shuffling each block on its own still hands out the first n points, and a power-of-two shuffle
// needs neither a cycle walk nor a division (with Kensler's permutation of all of [0, n), an
// 83-spp draw cost 1.7x a 64-spp one).
struct IndexBlock {
  uint32_t start, size;
};
ENVGI_INLINE IndexBlock powerOfTwoBlock(uint32_t i, uint32_t n) {
  uint32_t x = i ^ n;  // the highest bit where i (< n) and n differ: n has it, i has not
  for (uint32_t s = 1; s < 32; s <<= 1) x |= x >> s;
  uint32_t size = (x >> 1) + 1;  // that bit alone
  return {n & ~x, size};
}

// A shuffle of [0, size), size a power of two, whose every prefix [0, 2^j) goes onto an aligned
// block of 2^j: each bit of the index is flipped by a hash of the bits above it (nested uniform
// scrambling of the index, Burley 2020's shuffle). A (0,2)-sequence's aligned blocks are nets, so
// a pixel's first 2^j samples are stratified in every dimension pair whatever spp is: the
// viewer's frames, checkpoints and time-limited renders converge as a render of 2^j samples.
// (Kensler's permutation, used before, hands a prefix a scattered subset of the points.)
ENVGI_INLINE uint32_t nestedShuffle(uint32_t i, uint32_t size, uint32_t seed) {
  // Owen scrambling of i itself: each bit flipped by the bits above it; the bits at and above
  // log2(size) are zero, so the mask keeps a bijection.
  return owenScrambleReversed(reverseBits32(i), seed) & (size - 1);
}

// Salts that give each use of a pixel's hash its own stream.
inline constexpr uint32_t kSobolShuffle1D = 0x5bd1e995u, kSobolShuffle2D = 0x68e31da4u;
inline constexpr uint32_t kOwenSeedX = 0x1234567u, kOwenSeedY = 0x89abcdeu;

// A pixel's hash under a sequence's seed, from which every draw of its samples is made.
ENVGI_INLINE uint64_t pixelHashOf(uint64_t pixel, uint32_t seed) { return hashCombine(mixBits(pixel), seed); }

// The Sobol point of a pixel's first spp that sample indexInPixel takes in a dimension with hash
// h: a shuffle within the sample's power-of-two block (for a power of two, one shuffle of all spp);
// hashed, the point's own scramble is seeded from the same h.
ENVGI_INLINE uint32_t sobolShuffledIndex(uint32_t h, uint32_t indexInPixel, IndexBlock block, uint32_t blockSeed) {
  return block.start + nestedShuffle(indexInPixel - block.start, block.size, uint32_t(mixBits(h ^ blockSeed)));
}

// Sampler::get2D's Sobol draw in dimensions (d, d + 1) as a pure function of the pixel's hash and
// the sample, so that an executor can draw one dimension pair of many pixels in a loop the
// compiler vectorises; get2D itself calls it. Independent shuffles per dimension
// pair decorrelate the pairs (Burley 2020).
ENVGI_INLINE Vec2f sobolDraw2D(uint64_t pixelHash, uint32_t d, uint32_t indexInPixel, IndexBlock block,
                               uint32_t blockSeed) {
  uint32_t h = uint32_t(hashCombine(pixelHash, d));
  uint32_t i = sobolShuffledIndex(h ^ kSobolShuffle2D, indexInPixel, block, blockSeed);
  uint32_t s0 = uint32_t(mixBits(h ^ kOwenSeedX)), s1 = uint32_t(mixBits(h ^ kOwenSeedY));
  return {bitsToFloat01(owenScrambleReversed(sobolDim0Reversed(i), s0)),
          bitsToFloat01(owenScrambleReversed(sobolDim1Reversed(i), s1))};
}
// Photon emission draws from its own streams of the scene's seed, never the camera's.
inline constexpr uint32_t kPhotonMapStream = 0x9e3779b9u, kSppmPhotonStream = 0x85ebca6bu;
inline constexpr uint32_t kGridGatherStream = 0xc2b2ae35u, kCausticPhotonStream = 0x27d4eb2fu;

struct Sampler {
  SamplerType type = SamplerType::Independent;
  uint32_t spp = 1;
  uint32_t seed = 0;
  uint64_t pixelHash = 0;
  uint32_t index = 0;
  uint32_t indexInPixel = 0;  // index % spp, taken once a sample rather than once a draw
  IndexBlock block{0, 1};     // Sobol: the power-of-two block of [0, spp) indexInPixel is in
  // Sobol: salts the shuffle of each block after the first (0 there, so a power of two is as it
  // was). Unsalted, block [64, 96)'s shuffle was block [0, 64)'s mod 32: its sample k took
  // point 64 + (j mod 32) where the first block's took j, in the same 1/32 of every dimension.
  uint32_t blockSeed = 0;
  uint32_t dim = 0;
  Pcg32 rng;

  // Sobol: the point of the pixel's first spp this sample takes in a dimension with hash h.
  ENVGI_HD uint32_t shuffledIndex(uint32_t h) const { return sobolShuffledIndex(h, indexInPixel, block, blockSeed); }

  // Begin sample `sampleIndex` of a pixel (a pixel id, or any stream id for non-image work).
  ENVGI_HD void start(uint64_t pixel, uint32_t sampleIndex) {
    setIndex(sampleIndex);
    startPixel(pixel);
  }
  // start() in two halves, for an executor that starts sample s of many pixels at once: what
  // depends on the sample index alone (a division and a loop), once; then each pixel's part.
  ENVGI_HD void setIndex(uint32_t sampleIndex) {
    index = sampleIndex;
    indexInPixel = sampleIndex % spp;
    block = powerOfTwoBlock(indexInPixel, spp);
    blockSeed = block.start == 0 ? 0u : uint32_t(mixBits(block.start));
  }
  ENVGI_HD void startPixel(uint64_t pixel) {
    pixelHash = pixelHashOf(pixel, seed);
    dim = 0;
    // Sobol never reads the generator (nor steps it in skip1D/skip2D).
    if (type != SamplerType::Sobol) rng.setSeed(pixelHash, uint64_t(index) + 1u);
  }

  // startPixel for Sobol, where the pixel's hash is known and its first `drawn` dimensions were
  // drawn elsewhere, from sobolDraw2D: the next draw is the one after them.
  ENVGI_HD void startPixelAt(uint64_t hash, uint32_t drawn) {
    pixelHash = hash;
    dim = drawn;
  }

  ENVGI_HD float get1D() {
    uint32_t d = dim++;
    switch (type) {
      case SamplerType::Stratified: {
        uint32_t h = uint32_t(hashCombine(pixelHash, d));
        uint32_t s = permutationElement(indexInPixel, spp, h);
        return (float(s) + rng.nextFloat()) / float(spp) * kOneMinusEpsilon;
      }
      case SamplerType::Sobol: {
        uint32_t h = uint32_t(hashCombine(pixelHash, d));
        uint32_t i = shuffledIndex(h ^ kSobolShuffle1D);
        return bitsToFloat01(owenScrambleReversed(sobolDim0Reversed(i), h));
      }
      case SamplerType::Independent: break;
    }
    return rng.nextFloat();
  }

  // Past a draw whose value would go unused, as get1D() and get2D() would go: every later draw
  // is the one it would have been (the generator steps as often), for the cost of a step or none.
  ENVGI_HD void skip1D() {
    ++dim;
    if (type != SamplerType::Sobol) rng.nextUInt();
  }
  ENVGI_HD void skip2D() {
    dim += 2;
    if (type != SamplerType::Sobol) rng.nextUInt(), rng.nextUInt();
  }
  // Past every draw before dimension d (at or after the position), as skip1D would go: where a
  // layout places a draw at an offset past a position.
  ENVGI_HD void skipTo(uint32_t d) {
    if (type == SamplerType::Sobol) dim = d > dim ? d : dim;
    else
      while (dim < d) skip1D();
  }
  // A draw that is taken only where it is used (zero where it is skipped).
  ENVGI_HD float get1DIf(bool used) {
    if (used) return get1D();
    skip1D();
    return 0.f;
  }
  ENVGI_HD Vec2f get2DIf(bool used) {
    if (used) return get2D();
    skip2D();
    return {0.f, 0.f};
  }

  ENVGI_HD Vec2f get2D() {
    uint32_t d = dim;
    dim += 2;
    switch (type) {
      case SamplerType::Stratified: {
        // Jittered grid of nx * ny strata; a sample count that is not a square still fills
        // every stratum of the largest grid that fits, then jitters the rest independently.
        uint32_t nx = uint32_t(std::sqrt(float(spp)));
        while ((nx + 1) * (nx + 1) <= spp) ++nx;
        uint32_t n = nx * nx;
        uint32_t h = uint32_t(hashCombine(pixelHash, d));
        if (index >= n) return {rng.nextFloat(), rng.nextFloat()};
        uint32_t s = permutationElement(index, n, h);
        float jx = rng.nextFloat(), jy = rng.nextFloat();
        return {(float(s % nx) + jx) / float(nx) * kOneMinusEpsilon, (float(s / nx) + jy) / float(nx) * kOneMinusEpsilon};
      }
      case SamplerType::Sobol: return sobolDraw2D(pixelHash, d, indexInPixel, block, blockSeed);
      case SamplerType::Independent: break;
    }
    float a = rng.nextFloat();
    return {a, rng.nextFloat()};
  }
};

}  // namespace envgi
