#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "core/Atan2.h"

namespace envgi {
namespace {

// Largest error against double-precision atan2 over the whole circle, fine near the axes and
// diagonals where the octant reduction switches branch.
TEST(Atan2, WithinFourTenthsOfAMicroradianEverywhere) {
  double worst = 0.0;
  auto check = [&](float y, float x) {
    double err = std::fabs(double(polyAtan2(y, x)) - std::atan2(double(y), double(x)));
    worst = std::max(worst, err);
  };
  const int n = 1 << 20;
  for (int i = 0; i < n; ++i) {
    double phi = 2.0 * M_PI * (i + 0.5) / n;
    check(float(std::sin(phi)), float(std::cos(phi)));
  }
  for (float y : {0.f, 1e-30f, 1e-7f, 0.5f, 1.f, 1e7f})
    for (float x : {1e-30f, 1e-7f, 0.5f, 1.f, 1.0000001f, 1e7f})
      for (float sy : {1.f, -1.f})
        for (float sx : {1.f, -1.f}) check(sy * y, sx * x);
  std::mt19937 rng(5);
  std::uniform_real_distribution<float> d(-3.f, 3.f);
  for (int i = 0; i < 200000; ++i) check(d(rng), d(rng));
  EXPECT_LT(worst, 4e-7);  // libm itself is within 2.4e-7 (one ulp of pi)
}

// The quadrants and signed zeros that the map's seam depends on: u = atan2(x, -z) must not
// jump by 2 pi between -0 and +0 except where std::atan2 does.
TEST(Atan2, QuadrantsAndSignedZerosMatchStd) {
  for (float y : {0.f, -0.f, 1.f, -1.f})
    for (float x : {0.f, 1.f, -1.f}) {
      float a = polyAtan2(y, x), b = std::atan2(y, x);
      EXPECT_NEAR(a, b, 4e-7f) << y << ", " << x;
      EXPECT_EQ(std::signbit(a), std::signbit(b)) << y << ", " << x;
    }
  EXPECT_TRUE(std::isnan(polyAtan2(NAN, 1.f)));
  EXPECT_TRUE(std::isnan(polyAtan2(1.f, NAN)));
}

}  // namespace
}  // namespace envgi
