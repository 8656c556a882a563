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
