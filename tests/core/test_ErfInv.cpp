#include <gtest/gtest.h>

#include <cmath>

#include "core/ErfInv.h"

namespace envgi {
namespace {

// erf(erfInv(x)) = x across (-1, 1), the tails included, where Beckmann sampling draws its
// steepest slopes; measured in x's own units near the ends (1 - |x| down to 1e-7).
TEST(ErfInv, InvertsErfAcrossTheOpenInterval) {
  double worst = 0.0;
  auto check = [&](float x) {
    double y = erfInv(x);
    ASSERT_TRUE(std::isfinite(y)) << x;
    double back = std::erf(y);
    double scale = std::max(1e-7, std::min(std::fabs(double(x)), 1.0 - std::fabs(double(x))));
    worst = std::max(worst, std::fabs(back - x) / scale);
  };
  const int n = 1 << 18;
  for (int i = 1; i < n; ++i) check(-1.f + 2.f * float(i) / n);
  for (float t : {1e-7f, 1e-6f, 1e-5f, 1e-4f, 1e-3f, 1e-2f}) {
    check(1.f - t);
    check(-1.f + t);
  }
  for (float x : {1e-30f, 1e-7f, 1e-3f}) {
    check(x);
    check(-x);
  }
  EXPECT_LT(worst, 1e-5);  // float rounding of x itself is 6e-8 next to 1
  EXPECT_EQ(erfInv(0.f), 0.f);
  EXPECT_EQ(erfInv(-0.5f), -erfInv(0.5f));  // odd
}

}  // namespace
}  // namespace envgi
