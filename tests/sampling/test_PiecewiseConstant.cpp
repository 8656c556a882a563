#include <gtest/gtest.h>

#include <vector>

#include "sampling/Pcg32.h"
#include "sampling/PiecewiseConstant2D.h"

using namespace envgi;

TEST(PiecewiseConstant1D, SamplesFollowTheFunction) {
  std::vector<float> f = {1.f, 0.f, 3.f, 4.f};
  PiecewiseConstant1D d(f);
  EXPECT_FLOAT_EQ(d.integral(), 2.f);
  auto v = d.view();
  Pcg32 rng(1);
  std::vector<int> hist(4, 0);
  const int n = 200000;
  for (int i = 0; i < n; ++i) {
    float pdf;
    int off;
    float x = v.sample(rng.nextFloat(), &pdf, &off);
    ASSERT_GE(x, 0.f);
    ASSERT_LT(x, 1.f);
    ASSERT_EQ(off, int(x * 4));
    ASSERT_FLOAT_EQ(pdf, v.pdf(x));
    hist[off]++;
  }
  EXPECT_EQ(hist[1], 0);
  EXPECT_NEAR(hist[0] / double(n), 1.0 / 8, 0.005);
  EXPECT_NEAR(hist[2] / double(n), 3.0 / 8, 0.005);
  EXPECT_NEAR(hist[3] / double(n), 4.0 / 8, 0.005);
}

TEST(PiecewiseConstant1D, InvertRoundTrips) {
  std::vector<float> f = {0.5f, 2.f, 1.f, 7.f, 0.1f};
  PiecewiseConstant1D d(f);
  auto v = d.view();
  for (float u = 0.01f; u < 1.f; u += 0.0137f) {
    float x = v.sample(u, nullptr, nullptr);
    EXPECT_NEAR(v.invert(x), u, 1e-5f);
  }
}

TEST(PiecewiseConstant1D, AllZeroIsUniformWithoutNaN) {
  std::vector<float> f(16, 0.f);
  PiecewiseConstant1D d(f);
  auto v = d.view();
  for (float u = 0.f; u < 1.f; u += 0.01f) {
    float pdf;
    float x = v.sample(u, &pdf, nullptr);
    EXPECT_TRUE(std::isfinite(x));
    EXPECT_FLOAT_EQ(pdf, 1.f);
  }
}

TEST(PiecewiseConstant1D, NegativeAndNaNWeightsAreZero) {
  std::vector<float> f = {-1.f, NAN, 2.f, INFINITY};
  PiecewiseConstant1D d(f);
  auto v = d.view();
  EXPECT_FLOAT_EQ(v.pdf(0.1f), 0.f);
  EXPECT_FLOAT_EQ(v.pdf(0.3f), 0.f);
  EXPECT_FLOAT_EQ(v.pdf(0.6f), 4.f);
  EXPECT_FLOAT_EQ(v.pdf(0.9f), 0.f);
}

// The guided search must pick exactly the interval binary search picks, for every u: on a
// peaked function with runs of zeros (empty intervals), for guides coarser and finer than it,
// and at the guide's own cut points and their float neighbours.
TEST(PiecewiseConstant1D, GuidedSearchEqualsBinarySearch) {
  std::vector<float> f(3001, 0.f);
  Pcg32 rng(7);
  for (size_t i = 0; i < f.size(); ++i) f[i] = (i % 17 < 5) ? 0.f : rng.nextFloat() * rng.nextFloat();
  f[1234] = 5000.f;  // a sun: most of the mass in one interval
  PiecewiseConstant1D d(f);
  const float* cdf = d.view().cdf;
  int size = d.size() + 1;
  for (int G : {1, 2, 64, 1024, 8192}) {
    std::vector<int> guide(size_t(G) + 1);
    buildGuide(cdf, size, G, guide.data());
    std::vector<float> us;
    for (int i = 0; i < 100000; ++i) us.push_back(rng.nextFloat());
    for (int g = 0; g < G; ++g) {
      float c = float(g) / float(G);
      us.insert(us.end(), {c, std::nextafter(c, 0.f), std::nextafter(c, 1.f)});
    }
    us.push_back(kOneMinusEpsilon);
    for (float u : us) ASSERT_EQ(findIntervalGuided(cdf, u, guide.data(), G), findInterval(cdf, size, u)) << "G " << G << " u " << u;
  }
  // The branch-free search the guide hands its range to, on any range, an empty one and NaN.
  for (int i = 0; i < 20000; ++i) {
    int lo = int(rng.nextUInt() % uint32_t(size)), hi = lo + int(rng.nextUInt() % 40u) - 5;
    hi = hi < size - 1 ? hi : size - 1;
    float u = i % 1000 == 0 ? std::nanf("") : rng.nextFloat();
    ASSERT_EQ(findIntervalBetweenNoBranch(cdf, lo, hi, u), findIntervalBetween(cdf, lo, hi, u)) << lo << " " << hi;
  }
  std::vector<int> guide(4);
  EXPECT_THROW(buildGuide(cdf, size, 3, guide.data()), std::invalid_argument);
  EXPECT_EQ(guideSize(2048, 4), 512);
  EXPECT_EQ(guideSize(2049, 4), 1024);
  EXPECT_EQ(guideSize(1, 4), 1);
}

TEST(PiecewiseConstant2D, PdfIntegratesToOneAndMatchesSampling) {
  const int w = 7, h = 5;
  std::vector<float> f(w * h);
  Pcg32 rng(3);
  for (float& x : f) x = rng.nextFloat() < 0.3f ? 0.f : rng.nextFloat() * 10.f;
  PiecewiseConstant2D d(f.data(), w, h);
  auto v = d.view();
  double integral = 0.0;
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) integral += v.pdf(Vec2f((x + 0.5f) / w, (y + 0.5f) / h)) / (w * h);
  EXPECT_NEAR(integral, 1.0, 1e-5);
  std::vector<double> hist(w * h, 0.0);
  const int n = 400000;
  for (int i = 0; i < n; ++i) {
    float pdf;
    Vec2f p = v.sample(Vec2f(rng.nextFloat(), rng.nextFloat()), &pdf);
    ASSERT_NEAR(pdf, v.pdf(p), 1e-4f * pdf);
    ASSERT_GT(pdf, 0.f);
    hist[int(p.y * h) * w + int(p.x * w)] += 1.0;
    Vec2f back = v.invert(p);
    Vec2f again = v.sample(back, nullptr);
    ASSERT_NEAR(again.x, p.x, 1e-4f);
    ASSERT_NEAR(again.y, p.y, 1e-4f);
  }
  for (int c = 0; c < w * h; ++c) {
    double expected = v.pdf(Vec2f((c % w + 0.5f) / w, (c / w + 0.5f) / h)) / (w * h);
    EXPECT_NEAR(hist[c] / n, expected, 4.0 * std::sqrt(expected / n) + 1e-9) << "cell " << c;
  }
}
