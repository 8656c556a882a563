// ActivePixels (render/ActivePixels.h) against a scripted executor: samples count only for the
// pixels still active, a check stops the converged ones and hands the executor the new mask,
// and adaptive sampling is off where the threshold is 0 or the executor cannot mask pixels.
#include <gtest/gtest.h>

#include <stdexcept>

#include "render/ActivePixels.h"

using namespace envgi;

namespace {

// A film whose left half is flat (every sample 1: no noise) and right half noisy (0 and 2 in
// turn), with the masks it was handed.
struct ScriptedExecutor : PassExecutor {
  int W, H;
  bool masks = true, variance = true;
  std::vector<std::vector<unsigned char>> handed;
  std::vector<int> samples;
  ScriptedExecutor(int w, int h) : W(w), H(h), samples(size_t(w) * h, 0) {}
  std::string deviceName() const override { return "script"; }
  void runPass(int s0, int s1, Progress&, PassCounters*) override {
    const std::vector<unsigned char>* m = handed.empty() ? nullptr : &handed.back();
    for (size_t i = 0; i < samples.size(); ++i)
      if (!m || (*m)[i]) samples[i] += s1 - s0;
  }
  void readFilm(FilmSums* out) override {
    out->sum.assign(samples.size(), Color(0.f));
    out->sumSqLum.assign(samples.size(), 0.0);
    for (size_t i = 0; i < samples.size(); ++i) {
      int n = samples[i];
      bool flat = int(i % size_t(W)) < W / 2;
      out->sum[i] = Color(float(n));                    // mean 1 either way
      out->sumSqLum[i] = flat ? double(n) : 2.0 * n;    // 0, 2, 0, 2...: variance 1
    }
  }
  bool setActivePixels(const std::vector<unsigned char>& mask) override {
    if (!masks) return false;
    handed.push_back(mask);
    return true;
  }
  bool keepsVariance() const override { return variance; }
};

}  // namespace

TEST(ActivePixels, ConvergedPixelsStopAndTheExecutorGetsTheMask) {
  const int W = 12, H = 4;
  ScriptedExecutor ex(W, H);
  ActivePixels px(W, H, 0.05f);
  ASSERT_TRUE(px.attach(ex));
  ASSERT_EQ(ex.handed.size(), 1u);
  EXPECT_EQ(px.activeCount(), size_t(W * H));
  Progress quiet(1, false);
  ex.runPass(0, 8, quiet, nullptr);
  px.passDone(0, 8);
  EXPECT_EQ(px.pixelSamples(), uint64_t(W * H * 8));
  FilmSums film;
  size_t left = px.update(ex, &film);
  // The flat half converged; its column next to the noisy half keeps sampling (neighbours).
  EXPECT_EQ(left, size_t((W / 2 + 1) * H));
  ASSERT_EQ(ex.handed.size(), 2u) << "the new mask went to the executor";
  for (int y = 0; y < H; ++y)
    for (int x = 0; x < W; ++x) EXPECT_EQ(ex.handed.back()[size_t(y) * W + x], x >= W / 2 - 1 ? 1 : 0) << x;
  ex.runPass(8, 16, quiet, nullptr);
  px.passDone(8, 16);
  EXPECT_EQ(px.samples()[0], 8) << "a stopped pixel keeps the samples it had";
  EXPECT_EQ(px.samples()[W - 1], 16);
  EXPECT_EQ(px.pixelSamples(), uint64_t(W * H * 8 + left * 8));
  EXPECT_DOUBLE_EQ(px.meanSamples(), (8.0 * (W * H - left) + 16.0 * left) / (W * H));
  EXPECT_FALSE(px.converged());
}

TEST(ActivePixels, OffWithoutAThresholdOrAMaskingExecutor) {
  ScriptedExecutor ex(4, 4);
  ActivePixels off(4, 4, 0.f);
  EXPECT_FALSE(off.attach(ex));
  EXPECT_TRUE(ex.handed.empty()) << "no threshold: the executor is not asked to mask";
  off.passDone(0, 3);
  EXPECT_EQ(off.samples()[5], 3);
  EXPECT_DOUBLE_EQ(off.meanSamples(), 3.0);
  EXPECT_FALSE(off.converged());

  ex.masks = false;  // SPPM
  ActivePixels sppm(4, 4, 0.1f);
  EXPECT_FALSE(sppm.attach(ex));
  EXPECT_FALSE(sppm.adaptive());

  ex.masks = true;
  ex.variance = false;
  ActivePixels blind(4, 4, 0.1f);
  EXPECT_THROW(blind.attach(ex), std::logic_error);
}

TEST(ActivePixels, EveryPixelFlatConverges) {
  // A film of flat pixels everywhere: its right half made flat too.
  struct Flat : ScriptedExecutor {
    using ScriptedExecutor::ScriptedExecutor;
    void readFilm(FilmSums* out) override {
      ScriptedExecutor::readFilm(out);
      for (size_t i = 0; i < samples.size(); ++i) out->sumSqLum[i] = double(samples[i]);
    }
  } flat(4, 2);
  ActivePixels px(4, 2, 0.05f);
  ASSERT_TRUE(px.attach(flat));
  Progress quiet(1, false);
  flat.runPass(0, 4, quiet, nullptr);
  px.passDone(0, 4);
  FilmSums film;
  EXPECT_EQ(px.update(flat, &film), 0u);
  EXPECT_TRUE(px.converged());
  EXPECT_EQ(flat.handed.size(), 1u) << "no mask is handed once none is left";
}
