#include <gtest/gtest.h>

#include <vector>

#include "sampling/AliasTable.h"
#include "sampling/Pcg32.h"

using namespace envgi;

TEST(AliasTable, MatchesWeightsAndRemapsUniformly) {
  std::vector<float> w = {1.f, 0.f, 5.f, 2.f, 0.5f, 1.5f};
  AliasTable t(w.data(), w.size());
  auto v = t.view();
  Pcg32 rng(9);
  const int n = 600000;
  std::vector<double> hist(w.size(), 0.0);
  double remapMean = 0.0;
  for (int i = 0; i < n; ++i) {
    float pmf, ur;
    float u1 = rng.nextFloat();
    int k = v.sample(u1, rng.nextFloat(), &pmf, &ur);
    ASSERT_GE(ur, 0.f);
    ASSERT_LT(ur, 1.f);
    ASSERT_FLOAT_EQ(pmf, w[k] / 10.f);
    hist[k] += 1.0;
    remapMean += ur;
  }
  for (size_t k = 0; k < w.size(); ++k) EXPECT_NEAR(hist[k] / n, w[k] / 10.0, 0.003) << k;
  EXPECT_NEAR(remapMean / n, 0.5, 0.003);
}

TEST(AliasTable, AllZeroIsUniform) {
  std::vector<float> w(8, 0.f);
  AliasTable t(w.data(), w.size());
  auto v = t.view();
  float pmf;
  v.sample(0.3f, 0.6f, &pmf, nullptr);
  EXPECT_FLOAT_EQ(pmf, 1.f / 8.f);
}
