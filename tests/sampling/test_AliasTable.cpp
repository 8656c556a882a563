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
    int k = v.sample(Vec2f(u1, rng.nextFloat()), &pmf, &ur);
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
  v.sample(Vec2f(0.3f, 0.6f), &pmf, nullptr);
  EXPECT_FLOAT_EQ(pmf, 1.f / 8.f);
}

// Maps of 2000x1000 and 3000x1500 pixels (not powers of two): with 24-bit sample floats, every
// bin is chosen in proportion to its pmf. Chi-square over all bins, 2^25 draws: a bin choice
// from u.x alone (8 or 9 grid points a bin) gives a statistic hundreds of sigma off.
TEST(AliasTable, EveryBinOfLargeTablesAtItsPmf) {
  for (int w : {2000, 3000}) {
    int h = w / 2;
    size_t n = size_t(w) * h;
    std::vector<float> weight(n);
    Pcg32 wr(5);
    for (float& x : weight) x = 0.5f + wr.nextFloat();  // no bin too small to be counted
    AliasTable t(weight.data(), n);
    auto v = t.view();
    std::vector<uint32_t> count(n, 0);
    Pcg32 rng(11);
    const size_t draws = size_t(1) << 25;
    for (size_t k = 0; k < draws; ++k) ++count[size_t(v.sample(Vec2f(rng.nextFloat(), rng.nextFloat()), nullptr, nullptr))];
    double chi2 = 0.0;
    for (size_t i = 0; i < n; ++i) {
      double e = double(draws) * v.pmf(int(i));
      chi2 += (count[i] - e) * (count[i] - e) / e;
    }
    double z = (chi2 - double(n - 1)) / std::sqrt(2.0 * double(n - 1));
    EXPECT_LT(std::fabs(z), 5.0) << w << "x" << h << ": chi2 " << chi2 << " over " << n - 1 << " dof";
  }
}

// What the choice leaves over is still uniform, finely: 64 strata of it are equally full even
// for 2^22 bins (the position inside an environment-map pixel comes from it).
TEST(AliasTable, LeftoverStaysUniformForManyBins) {
  size_t n = size_t(1) << 22;
  std::vector<float> weight(n, 1.f);
  weight[7] = 1000.f;
  AliasTable t(weight.data(), n);
  auto v = t.view();
  Pcg32 rng(3);
  const int draws = 1 << 20, strata = 64;
  std::vector<int> hist(strata, 0);
  for (int k = 0; k < draws; ++k) {
    float r;
    v.sample(Vec2f(rng.nextFloat(), rng.nextFloat()), nullptr, &r);
    ASSERT_GE(r, 0.f);
    ASSERT_LT(r, 1.f);
    ++hist[int(r * strata)];
  }
  double chi2 = 0.0, e = double(draws) / strata;
  for (int c : hist) chi2 += (c - e) * (c - e) / e;
  EXPECT_LT(chi2, 120.0);  // 63 dof: p < 1e-5 above this
}
