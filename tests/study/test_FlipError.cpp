// FLIP against NVIDIA's reference implementation (flip-evaluator 1.7 from PyPI): the mean and six
// pixels of the LDR and HDR error maps of two formula images, which scripts/flip_reference.py
// writes the same way and prints these values from.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "study/FlipError.h"

using namespace envgi;

namespace {

constexpr int kW = 40, kH = 32;

void formulaPair(bool hdr, Image* ref, Image* test) {
  *ref = Image(kW, kH), *test = Image(kW, kH);
  for (int y = 0; y < kH; ++y)
    for (int x = 0; x < kW; ++x)
      for (int c = 0; c < 3; ++c) {
        double r = 0.5 + 0.4 * std::sin(0.31 * x + 0.17 * y + 1.3 * c);
        double t = r + 0.15 * std::sin(1.7 * x * y + 0.9 * c) * (x > kW / 2 ? 1.0 : 0.0);
        if (hdr) {
          const double bright = (x - 10) * (x - 10) + (y - 12) * (y - 12) < 9 ? 40.0 : 1.0;
          r = 4.0 * r * bright;
          t = std::max(0.0, 4.0 * t * bright * (y > 24 ? 1.3 : 1.0));
        } else {
          t = std::clamp(t, 0.0, 1.0);
        }
        const size_t k = 3 * (size_t(y) * kW + size_t(x)) + size_t(c);
        ref->rgb[k] = float(r), test->rgb[k] = float(t);
      }
}

struct Pixel {
  int x, y;
  float ldr, hdr;
};
// flip_reference.py's output.
constexpr Pixel kPixels[] = {{21, 5, 0.1239247f, 0.1223744f}, {25, 3, 0.1729853f, 0.1807070f},
                             {30, 20, 0.0598624f, 0.0658070f}, {5, 28, 0.0000000f, 0.3124816f},
                             {20, 10, 0.0680133f, 0.1712855f}, {39, 31, 0.2295967f, 0.3919580f}};
constexpr double kMeanLdr = 0.0735940, kMeanHdr = 0.1595426;

}  // namespace

// A map's mean and pixels against flip_reference.py's values.
static void expectReference(const std::vector<float>& map, double mean, float Pixel::*value) {
  EXPECT_NEAR(flipMean(map), mean, 1e-5);
  for (const Pixel& p : kPixels) EXPECT_NEAR(map[size_t(p.y * kW + p.x)], p.*value, 5e-5) << p.x << ", " << p.y;
}

TEST(FlipError, LdrMatchesTheReferenceImplementation) {
  Image ref, test;
  formulaPair(false, &ref, &test);
  expectReference(flipLdr(ref, test), kMeanLdr, &Pixel::ldr);
}

TEST(FlipError, HdrMatchesTheReferenceImplementation) {
  Image ref, test;
  formulaPair(true, &ref, &test);
  const FlipExposures e = flipExposures(ref);
  EXPECT_NEAR(e.start, -5.84414005f, 1e-4);
  EXPECT_NEAR(e.stop, 0.04917419f, 1e-4);
  EXPECT_EQ(e.count, 6);
  expectReference(flipHdr(ref, test), kMeanHdr, &Pixel::hdr);
}

TEST(FlipError, AnImageAgainstItselfIsZeroAndSizesMustAgree) {
  Image ref, test;
  formulaPair(true, &ref, &test);
  for (float v : flipHdr(ref, ref)) ASSERT_EQ(v, 0.f);
  const Image black(kW, kH);
  for (float v : flipHdr(black, black)) ASSERT_EQ(v, 0.f);
  EXPECT_THROW(flipLdr(ref, Image(kW, kH + 1)), std::runtime_error);
}
