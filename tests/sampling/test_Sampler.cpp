#include <gtest/gtest.h>

#include <cmath>
#include <set>
#include <vector>

#include "sampling/Sampler.h"

using namespace envgi;

namespace {
Sampler sampler(SamplerType t, uint32_t spp, uint32_t seed) {
  Sampler s;
  s.type = t;
  s.spp = spp;
  s.seed = seed;
  return s;
}

std::vector<Vec2f> draw(SamplerType t, uint32_t spp, uint32_t seed, uint64_t pixel) {
  Sampler s = sampler(t, spp, seed);
  std::vector<Vec2f> out;
  for (uint32_t i = 0; i < spp; ++i) {
    s.start(pixel, i);
    out.push_back(s.get2D());
  }
  return out;
}
}  // namespace

class SamplerTypes : public ::testing::TestWithParam<SamplerType> {};

TEST_P(SamplerTypes, ReproducibleAndInRange) {
  auto a = draw(GetParam(), 64, 5, 17), b = draw(GetParam(), 64, 5, 17), c = draw(GetParam(), 64, 6, 17);
  bool differs = false;
  for (size_t i = 0; i < a.size(); ++i) {
    EXPECT_EQ(a[i].x, b[i].x);
    EXPECT_EQ(a[i].y, b[i].y);
    EXPECT_GE(a[i].x, 0.f);
    EXPECT_LT(a[i].x, 1.f);
    EXPECT_GE(a[i].y, 0.f);
    EXPECT_LT(a[i].y, 1.f);
    differs = differs || a[i].x != c[i].x;
  }
  EXPECT_TRUE(differs) << "another seed must give other samples";
}

TEST_P(SamplerTypes, MeanIsOneHalf) {
  double sx = 0, sy = 0;
  int n = 0;
  for (uint64_t px = 0; px < 200; ++px)
    for (Vec2f p : draw(GetParam(), 16, 1, px)) {
      sx += p.x;
      sy += p.y;
      ++n;
    }
  EXPECT_NEAR(sx / n, 0.5, 0.01);
  EXPECT_NEAR(sy / n, 0.5, 0.01);
}

// A skipped draw leaves every later one as it was (next-event estimation skips the draws a
// map-only scene never uses), at sample counts that are and are not a square or a power of two.
TEST_P(SamplerTypes, SkippedDrawsLeaveTheLaterOnesAsTheyWere) {
  for (uint32_t spp : {16u, 19u}) {
    Sampler drawn = sampler(GetParam(), spp, 3), skipped = drawn;
    for (uint32_t i = 0; i < spp; ++i) {
      drawn.start(42, i);
      skipped.start(42, i);
      for (int bounce = 0; bounce < 3; ++bounce) {
        drawn.get1D();
        skipped.skip1D();
        Vec2f a = drawn.get2D(), b = skipped.get2D();
        EXPECT_EQ(a.x, b.x);
        EXPECT_EQ(a.y, b.y);
        drawn.get2D();
        skipped.skip2D();
        EXPECT_EQ(drawn.get1D(), skipped.get1D()) << "sample " << i << ", bounce " << bounce;
      }
      EXPECT_EQ(drawn.dim, skipped.dim);
    }
  }
}

// start() in its two halves, as the CPU's camera stage runs it (setIndex once for sample s, then a
// copy per pixel and startPixel), draws what start() draws, at a power of two and not.
TEST_P(SamplerTypes, StartInTwoHalvesDrawsAsStart) {
  for (uint32_t spp : {16u, 19u}) {
    Sampler whole = sampler(GetParam(), spp, 7), first = whole;
    for (uint32_t s = 0; s < spp; ++s) {
      first.setIndex(s);
      for (uint64_t pixel : {0ull, 5ull, 1000003ull}) {
        Sampler halves = first;
        halves.startPixel(pixel);
        whole.start(pixel, s);
        for (int d = 0; d < 4; ++d) {
          Vec2f a = whole.get2D(), b = halves.get2D();
          EXPECT_EQ(a.x, b.x) << "sample " << s << ", pixel " << pixel;
          EXPECT_EQ(a.y, b.y);
          EXPECT_EQ(whole.get1D(), halves.get1D());
        }
      }
    }
  }
}

INSTANTIATE_TEST_SUITE_P(All, SamplerTypes,
                         ::testing::Values(SamplerType::Independent, SamplerType::Stratified, SamplerType::Sobol));

// Stratified and Sobol put exactly one of 16 samples into each cell of a 4x4 grid.
TEST(Sampler, StratifiedAndSobolAreStratified) {
  for (SamplerType t : {SamplerType::Stratified, SamplerType::Sobol}) {
    auto pts = draw(t, 16, 3, 99);
    std::set<int> cells;
    for (Vec2f p : pts) cells.insert(int(p.x * 4) + 4 * int(p.y * 4));
    EXPECT_EQ(cells.size(), 16u) << int(t);
  }
}

TEST(Sampler, PermutationIsBijective) {
  // Powers of two take the mask in place of the modulo; the others cycle-walk and divide.
  for (uint32_t n : {1u, 2u, 7u, 16u, 64u, 100u, 1024u}) {
    std::set<uint32_t> seen;
    for (uint32_t i = 0; i < n; ++i) seen.insert(permutationElement(i, n, 12345u));
    EXPECT_EQ(seen.size(), n);
    EXPECT_LT(*seen.rbegin(), n);
  }
}

// Power-of-two blocks split [0, n) by n's binary digits, and the shuffle within a block is a
// bijection whose every prefix [0, 2^j) lands on an aligned block of 2^j indices.
TEST(Sampler, PowerOfTwoBlocksShuffleTheFirstNIndices) {
  for (uint32_t n = 1; n <= 300; ++n)
    for (uint32_t h : {12345u, 0x9e3779b9u}) {
      std::set<uint32_t> seen;
      for (uint32_t i = 0; i < n; ++i) {
        IndexBlock b = powerOfTwoBlock(i, n);
        ASSERT_EQ(b.size & (b.size - 1), 0u) << n << " " << i;
        ASSERT_TRUE(b.start <= i && i < b.start + b.size && b.start + b.size <= n) << n << " " << i;
        ASSERT_EQ(b.start % b.size, 0u) << n << " " << i;  // aligned: a net of the (0,2)-sequence
        seen.insert(b.start + nestedShuffle(i - b.start, b.size, h));
      }
      EXPECT_EQ(seen.size(), n);
      EXPECT_LT(*seen.rbegin(), n);
    }
  for (uint32_t size : {1u, 2u, 64u, 1024u})
    for (uint32_t h : {1u, 777u, 0xdeadbeefu})
      for (uint32_t k = 1; k <= size; k *= 2) {
        std::set<uint32_t> blocks;  // which aligned block of k each of the first k lands in
        for (uint32_t i = 0; i < k; ++i) blocks.insert(nestedShuffle(i, size, h) / k);
        EXPECT_EQ(blocks.size(), 1u) << size << " " << h << " " << k;
      }
}

// A pixel's first 2^j Sobol samples, of any larger spp, fill the 2^j strata of each 1D dimension
// and the cells of each 2D pair's square grid once each: the viewer's frames, checkpoints and
// time-limited renders are as even as a render of 2^j samples.
TEST(Sampler, SobolPrefixesAtPowersOfTwoAreStratified) {
  for (uint32_t spp : {256u, 1000u}) {
    Sampler s;
    s.type = SamplerType::Sobol;
    s.spp = spp;
    s.seed = 9;
    for (uint32_t k : {4u, 16u, 64u}) {
      uint32_t g = uint32_t(std::lround(std::sqrt(double(k))));
      for (uint64_t pixel : {3u, 4242u}) {
        std::set<int> strata, cells, cellsDeep;
        for (uint32_t i = 0; i < k; ++i) {
          s.start(pixel, i);
          strata.insert(int(s.get1D() * k));
          Vec2f p = s.get2D();
          cells.insert(int(p.x * g) + int(g) * int(p.y * g));
          s.get1D();
          Vec2f q = s.get2D();
          cellsDeep.insert(int(q.x * g) + int(g) * int(q.y * g));
        }
        EXPECT_EQ(strata.size(), k) << spp << " " << k;
        EXPECT_EQ(cells.size(), k) << spp << " " << k;
        EXPECT_EQ(cellsDeep.size(), k) << spp << " " << k;
      }
    }
  }
}

// At any sample count, each Sobol dimension hands a pixel's samples exactly the first spp points
// of its scrambled sequence, in a shuffled order.
TEST(Sampler, SobolDrawsTheFirstSppPointsAtAnyCount) {
  for (uint32_t spp : {24u, 83u, 96u, 128u}) {
    Sampler s;
    s.type = SamplerType::Sobol;
    s.spp = spp;
    s.seed = 5;
    std::vector<std::multiset<float>> got(4);
    for (uint32_t i = 0; i < spp; ++i) {
      s.start(77, i);
      got[0].insert(s.get1D());
      Vec2f p = s.get2D();
      got[1].insert(p.x);
      got[2].insert(p.y);
      got[3].insert(s.get1D());
    }
    s.start(77, 0);
    uint32_t h0 = uint32_t(hashCombine(s.pixelHash, 0u)), h1 = uint32_t(hashCombine(s.pixelHash, 1u)),
             h3 = uint32_t(hashCombine(s.pixelHash, 3u));
    std::vector<std::multiset<float>> want(4);
    for (uint32_t j = 0; j < spp; ++j) {
      want[0].insert(bitsToFloat01(owenScrambleReversed(sobolDim0Reversed(j), h0)));
      want[1].insert(bitsToFloat01(owenScrambleReversed(sobolDim0Reversed(j), uint32_t(mixBits(h1 ^ kOwenSeedX)))));
      want[2].insert(bitsToFloat01(owenScrambleReversed(sobolDim1Reversed(j), uint32_t(mixBits(h1 ^ kOwenSeedY)))));
      want[3].insert(bitsToFloat01(owenScrambleReversed(sobolDim0Reversed(j), h3)));
    }
    for (int d = 0; d < 4; ++d) EXPECT_EQ(got[d], want[d]) << spp << " dimension " << d;
  }
}

// A count that is not a power of two takes its blocks' samples apart: at 96 spp the second
// block's sample k must not sit where the first block's sample k sits. With one shuffle for both
// blocks it did, in every dimension (the same 1/32 of it each time: a rate of 1 where 1/32 is
// chance), and textured-light at 96 spp had 1.26x the squared error it now has.
TEST(Sampler, SobolBlocksAreShuffledApart) {
  Sampler s;
  s.type = SamplerType::Sobol;
  s.spp = 96;
  s.seed = 3;
  int same = 0, pairs = 0;
  for (uint64_t pixel = 0; pixel < 500; ++pixel)
    for (uint32_t k = 0; k < 32; ++k) {
      float a[3], b[3];
      for (int blk = 0; blk < 2; ++blk) {
        s.start(pixel, blk * 64 + k);
        float* v = blk == 0 ? a : b;
        v[0] = s.get1D();
        Vec2f p = s.get2D();
        v[1] = p.x, v[2] = p.y;
      }
      for (int d = 0; d < 3; ++d) same += int(a[d] * 32.f) == int(b[d] * 32.f), ++pairs;
    }
  EXPECT_LT(double(same) / pairs, 0.05) << same << " of " << pairs;
  EXPECT_GT(double(same) / pairs, 0.015) << same << " of " << pairs;
}

// The fast forms the Sobol sampler draws through must give the very values of the plain ones:
// the byte-swap bit reversal, the dimensions built already reversed, the scrambler fed reversed
// input.
TEST(Sampler, FastFormsMatchThePlainOnes) {
  auto naiveReverse = [](uint32_t v) {
    uint32_t r = 0;
    for (int b = 0; b < 32; ++b) r |= ((v >> b) & 1u) << (31 - b);
    return r;
  };
  // The plain forms: Sobol's dimensions 0 and 1 in natural bit order, and Owen scrambling as
  // reverse, Laine-Karras hash, reverse.
  auto sobolDim0 = [&](uint32_t i) { return naiveReverse(i); };
  auto sobolDim1 = [](uint32_t i) {
    uint32_t r = 0;
    for (uint32_t v = 1u << 31; i; i >>= 1, v ^= v >> 1)
      if (i & 1u) r ^= v;
    return r;
  };
  auto owenScramble = [&](uint32_t v, uint32_t seed) {
    return naiveReverse(laineKarrasPermutation(naiveReverse(v), seed));
  };
  Pcg32 rng(11);
  for (int k = 0; k < 20000; ++k) {
    uint32_t v = rng.nextUInt(), seed = rng.nextUInt(), i = k < 4096 ? uint32_t(k) : v;
    ASSERT_EQ(reverseBits32(v), naiveReverse(v));
    ASSERT_EQ(sobolDim0Reversed(i), reverseBits32(sobolDim0(i)));
    ASSERT_EQ(sobolDim1Reversed(i), reverseBits32(sobolDim1(i)));
    ASSERT_EQ(owenScrambleReversed(reverseBits32(v), seed), owenScramble(v, seed));
  }
}
