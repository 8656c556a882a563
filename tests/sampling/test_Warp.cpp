#include <gtest/gtest.h>

#include "sampling/Mis.h"
#include "sampling/Warp.h"

using namespace envgi;

TEST(Warp, UnitLengthAndHemisphere) {
  for (float a = 0.f; a < 1.f; a += 0.07f)
    for (float b = 0.f; b < 1.f; b += 0.07f) {
      EXPECT_NEAR(length(sampleUniformSphere({a, b})), 1.f, 1e-5f);
      Vec3f c = sampleCosineHemisphere({a, b});
      EXPECT_NEAR(length(c), 1.f, 1e-5f);
      EXPECT_GE(c.z, 0.f);
    }
}

TEST(Mis, WeightsSumToOne) {
  float counts[3] = {1.f, 2.f, 1.f};
  float pdfs[3] = {0.3f, 1.7f, 0.05f};
  for (float beta : {1.f, 2.f}) {
    float sum = 0.f;
    for (int i = 0; i < 3; ++i) sum += misWeight(i, counts, pdfs, 3, beta);
    EXPECT_NEAR(sum, 1.f, 1e-6f);
  }
  EXPECT_NEAR(balanceHeuristic(1, 0.3f, 1, 0.7f) + balanceHeuristic(1, 0.7f, 1, 0.3f), 1.f, 1e-6f);
  EXPECT_NEAR(powerHeuristic(1, 0.3f, 1, 0.7f) + powerHeuristic(1, 0.7f, 1, 0.3f), 1.f, 1e-6f);
  // Eq. 4: zero weight where the strategy's pdf is zero.
  float pz[2] = {0.f, 1.f};
  EXPECT_EQ(misWeight(0, counts, pz, 2, 1.f), 0.f);
  EXPECT_EQ(misWeight(0, counts, pz, 2, 2.f), 0.f);
  EXPECT_EQ(balanceHeuristic(1, 0.f, 1, 0.f), 0.f);
  // Eq. 5-6 with sample counts: c_i p_i / sum c_k p_k.
  float c2[2] = {2.f, 1.f}, p2[2] = {0.5f, 1.f};
  EXPECT_FLOAT_EQ(misWeight(0, c2, p2, 2, 1.f), 0.5f);
  EXPECT_FLOAT_EQ(misWeight(0, c2, p2, 2, 1.f), balanceHeuristic(2.f, 0.5f, 1.f, 1.f));
}

// sampleTwoLinearPieces inverts the cdf of the piecewise-linear density through (0, n0),
// (1/2, n1), (1, n2): the exact cdf at the returned point is u, for node values that include
// zeros, equal pairs and a spike, and the point stays in [0, 1).
TEST(Warp, TwoLinearPiecesInvertTheirCdf) {
  const float nodes[][3] = {{1, 1, 1}, {0, 1, 0}, {1, 0, 1}, {0, 0, 5}, {3, 0, 0}, {0.2f, 7, 0.1f}, {1, 1, 4}, {2, 2, 0}};
  for (const auto& n : nodes) {
    // The cdf by the piece's trapezoid: area of [0, x] under the linear pieces, over the whole.
    auto cdf = [&](double x) {
      auto area = [](double a, double b, double t) { return 0.5 * (a * t + 0.5 * (b - a) * t * t); };  // [0, t] of a piece of width 1/2, t in [0, 1]
      double left = area(n[0], n[1], 1.0), total = left + area(n[1], n[2], 1.0);
      double part = x < 0.5 ? area(n[0], n[1], 2 * x) : left + area(n[1], n[2], 2 * x - 1);
      return part / total;
    };
    for (int k = 0; k < 1000; ++k) {
      float u = (k + 0.5f) / 1000.f;
      float x = sampleTwoLinearPieces(u, n[0], n[1], n[2]);
      ASSERT_GE(x, 0.f);
      ASSERT_LT(x, 1.f);
      ASSERT_NEAR(cdf(x), u, 2e-5) << n[0] << "," << n[1] << "," << n[2] << " u " << u;
    }
  }
  EXPECT_EQ(sampleTwoLinearPieces(0.3f, 0, 0, 0), 0.3f) << "uniform where the function is zero";
  EXPECT_FLOAT_EQ(twoLinearPieces(0.25f, 0, 2, 4), 1.f);
  EXPECT_FLOAT_EQ(twoLinearPieces(0.75f, 0, 2, 4), 3.f);
}
