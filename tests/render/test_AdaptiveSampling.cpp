// Adaptive sampling (render/AdaptiveSampling.h): the noise estimate against its definition, the
// mask's neighbourhood rule, and whole renders: stopped pixels had converged when they stopped,
// a threshold no pixel meets leaves the image bit for bit as without adaptive sampling, and the
// image of an adaptive render agrees with a full one.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <set>

#include "accel/EmbreeAccel.h"
#include "render/AdaptiveSampling.h"
#include "render/Renderer.h"
#include "scene/NameTables.h"
#include "scene/SceneLoader.h"
#include "support/BundledScene.h"
#include "support/ImageAgreement.h"
#include "support/SmallGrid.h"

using namespace envgi;

namespace {

// Sums of grey samples as the film keeps them.
struct PixelSums {
  Color sum{0.f};
  double sumSq = 0.0;
  int n = 0;
  void add(float v) {
    sum += Color(v);
    sumSq += double(v) * double(v);
    ++n;
  }
};

// A bundled scene at res x res with the path integrator, finalized.
void loadSmall(const std::string& name, int res, Scene* s) {
  test::loadBundledSmall(name, res, IntegratorType::Path, s);
  s->finalize();
}

struct Rendered {
  Image img;
  std::vector<float> var;
  std::vector<int> samples;
  RenderStats stats;
};

Rendered renderWith(const Scene& s, const EmbreeAccel& accel, int spp, float threshold, int minSpp) {
  RenderOptions o;
  o.progress = false;
  o.spp = spp;
  o.noiseThreshold = threshold;
  o.adaptiveMinSpp = minSpp;
  Rendered r;
  o.varianceOut = &r.var;
  o.samplesOut = &r.samples;
  r.img = render(s, accel, o, &r.stats);
  return r;
}

}  // namespace

TEST(AdaptiveSampling, PixelNoiseIsTheStandardErrorOverTheRootOfTheMean) {
  const float values[] = {0.2f, 1.7f, 0.4f, 3.1f, 0.9f, 0.0f, 2.2f};
  PixelSums p;
  for (float v : values) p.add(v);
  double mean = 0.0, ss = 0.0;
  for (float v : values) mean += v;
  mean /= p.n;
  for (float v : values) ss += (v - mean) * (v - mean);
  double expected = std::sqrt(ss / (p.n - 1) / p.n) / (1e-4 + std::sqrt(mean));
  EXPECT_NEAR(pixelNoise(p.sum, p.sumSq, p.n), expected, 1e-5 * expected);
  // Radiance four times brighter: the noise doubles (the root of the mean divides it).
  PixelSums q;
  for (float v : values) q.add(4.f * v);
  EXPECT_NEAR(pixelNoise(q.sum, q.sumSq, q.n), 2.0 * expected, 1e-4 * expected);
  // No spread, one sample, or a black pixel: no noise to measure.
  PixelSums flat, black;
  for (int i = 0; i < 8; ++i) flat.add(0.75f), black.add(0.f);
  EXPECT_NEAR(pixelNoise(flat.sum, flat.sumSq, flat.n), 0.f, 1e-6f);
  EXPECT_EQ(pixelNoise(black.sum, black.sumSq, black.n), 0.f);
  EXPECT_EQ(pixelNoise(Color(3.f), 9.0, 1), 0.f);
}

// One noisy pixel keeps its 3x3 neighbourhood sampling; the rest stops, for good.
TEST(AdaptiveSampling, APixelStopsOnlyWhenItsNeighboursHaveConverged) {
  const int W = 6, H = 5;
  const size_t px = W * H;
  std::vector<Color> sum(px, Color(8.f));  // 8 samples of 1: no noise
  std::vector<double> sumSq(px, 8.0);
  std::vector<int> samples(px, 8);
  const size_t noisy = 2 * W + 4;  // (4, 2)
  sum[noisy] = Color(8.f), sumSq[noisy] = 8.0 * 9.0;  // a spread of about 2.8 around a mean of 1
  std::vector<unsigned char> active(px, 1);
  EXPECT_EQ(updateActivePixels(sum, sumSq, samples, W, H, 0.05f, 1, &active), 9u);
  for (int y = 0; y < H; ++y)
    for (int x = 0; x < W; ++x)
      EXPECT_EQ(active[size_t(y) * W + x], std::abs(x - 4) <= 1 && std::abs(y - 2) <= 1) << x << "," << y;
  // A stopped pixel stays stopped even if its sums now looked noisy (they do not change once
  // it stops; stopping is final so its samples remain a prefix of its sequence).
  sumSq[0] = 8.0 * 9.0;
  EXPECT_EQ(updateActivePixels(sum, sumSq, samples, W, H, 0.05f, 1, &active), 9u);
  EXPECT_EQ(active[0], 0);
  // Once the noisy pixel has converged, everything stops.
  sumSq[noisy] = 8.0;
  EXPECT_EQ(updateActivePixels(sum, sumSq, samples, W, H, 0.05f, 1, &active), 0u);
  // Radius 0: only the noisy pixel itself would have been kept.
  std::vector<unsigned char> all(px, 1);
  sumSq[noisy] = 72.0, sumSq[0] = 8.0;
  EXPECT_EQ(updateActivePixels(sum, sumSq, samples, W, H, 0.05f, 0, &all), 1u);
  EXPECT_EQ(all[noisy], 1);
  std::vector<unsigned char> wrong(px - 1, 1);
  EXPECT_THROW(updateActivePixels(sum, sumSq, samples, W, H, 0.05f, 1, &wrong), std::invalid_argument);
}

// A whole render: every pixel that stopped early had, at its last sample, noise below the
// threshold; the counts are the pass ends; fewer samples are taken than without it.
TEST(AdaptiveSampling, StoppedPixelsHadConvergedAndTheRestTookEverySample) {
  Scene s;
  loadSmall("buddha", 32, &s);
  EmbreeAccel accel(s);
  const float threshold = 0.05f;
  Rendered r = renderWith(s, accel, 64, threshold, 8);
  ASSERT_EQ(r.stats.sppDone, 64);
  ASSERT_EQ(r.samples.size(), 32u * 32u);
  std::set<int> counts(r.samples.begin(), r.samples.end());
  for (int n : counts) EXPECT_TRUE(n == 8 || n == 16 || n == 32 || n == 64) << n;
  EXPECT_GT(r.stats.pixelsStopped, 100u) << "the map's background converges early";
  EXPECT_LT(r.stats.pixelsStopped, 32u * 32u) << "the buddha's glossy pixels do not";
  uint64_t taken = 0;
  for (int n : r.samples) taken += uint64_t(n);
  EXPECT_EQ(taken, r.stats.pixelSamples);
  EXPECT_LT(taken, uint64_t(32 * 32 * 64) * 3 / 4);
  for (size_t i = 0; i < r.samples.size(); ++i) {
    if (r.samples[i] == 64) continue;
    float lum = luminance(r.img.rgb[3 * i], r.img.rgb[3 * i + 1], r.img.rgb[3 * i + 2]);
    double noise = std::sqrt(double(r.var[i])) / (1e-4 + std::sqrt(std::max(0.0, double(lum))));
    EXPECT_LT(noise, threshold * 1.001) << "pixel " << i << " stopped at " << r.samples[i];
  }
}

// A threshold that no pixel meets keeps every pixel sampling: the masked passes add exactly what
// unmasked ones do, so the image is the same to the bit.
TEST(AdaptiveSampling, AThresholdNoPixelMeetsChangesNothing) {
  Scene s;
  loadSmall("teapot-glass", 24, &s);
  EmbreeAccel accel(s);
  Rendered plain = renderWith(s, accel, 16, 0.f, 16);
  Rendered masked = renderWith(s, accel, 16, 1e-12f, 2);
  EXPECT_EQ(masked.stats.pixelsStopped, 0u);
  EXPECT_EQ(masked.stats.pixelSamples, uint64_t(24 * 24 * 16));
  EXPECT_EQ(plain.stats.pixelSamples, uint64_t(24 * 24 * 16));
  ASSERT_EQ(plain.img.rgb.size(), masked.img.rgb.size());
  EXPECT_EQ(0, std::memcmp(plain.img.rgb.data(), masked.img.rgb.data(), plain.img.rgb.size() * sizeof(float)));
}

// The adaptive image agrees with a full render of the same samples everywhere (its pixels are
// prefixes of the full render's), within the noise the full render's variance predicts.
TEST(AdaptiveSampling, TheImageAgreesWithAFullRender) {
  Scene s;
  loadSmall("bunny-sunrise", 32, &s);
  EmbreeAccel accel(s);
  Rendered full = renderWith(s, accel, 64, 0.f, 16);
  Rendered adaptive = renderWith(s, accel, 64, 0.03f, 16);
  EXPECT_GT(adaptive.stats.pixelsStopped, 0u);
  test::ImageAgreement a = test::compareImages(full.img, adaptive.img);
  EXPECT_NEAR(a.meanRatio, 1.0, 0.01);
  // Each pixel's difference is that of a prefix of its own samples: at most a few of the
  // prefix's standard errors.
  int outliers = 0;
  for (size_t i = 0; i < full.samples.size(); ++i) {
    float lf = luminance(full.img.rgb[3 * i], full.img.rgb[3 * i + 1], full.img.rgb[3 * i + 2]);
    float la = luminance(adaptive.img.rgb[3 * i], adaptive.img.rgb[3 * i + 1], adaptive.img.rgb[3 * i + 2]);
    double sd = std::sqrt(double(adaptive.var[i]) + double(full.var[i])) + 1e-6;
    if (std::abs(lf - la) > 5.0 * sd) ++outliers;
  }
  EXPECT_LE(outliers, 3) << "of " << full.samples.size();
}

// SPPM's passes cover every pixel at once: it says so instead of rendering.
TEST(AdaptiveSampling, SppmRefusesANoiseThreshold) {
  Scene s;
  loadSmall("cornell-box", 16, &s);
  s.integrator.type = IntegratorType::Sppm;
  s.finalize();
  EmbreeAccel accel(s);
  RenderOptions o;
  o.progress = false;
  o.spp = 2;
  o.noiseThreshold = 0.01f;
  try {
    render(s, accel, o, nullptr);
    FAIL() << "sppm rendered with a noise threshold";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("not sppm"), std::string::npos) << e.what();
  }
}

// An executor made without per-pixel variance (RenderOptions::keepsVariance false) cannot
// judge noise: the loop says so before the first pass instead of after it.
TEST(AdaptiveSampling, AnExecutorWithoutVarianceIsRefusedBeforeAnyPass) {
  Scene s;
  loadSmall("buddha", 16, &s);
  EmbreeAccel accel(s);
  RenderOptions o;
  o.progress = false;
  o.spp = 4;
  PreparedRender pr = prepareRender(s, accel, o);
  o.noiseThreshold = 0.1f;
  RenderStats st;
  EXPECT_THROW(renderPasses(*pr.executor, 16, 16, 4, o, &st), std::logic_error);
  EXPECT_EQ(st.sppDone, 0);
  PreparedRender ok = prepareRender(s, accel, o);
  renderPasses(*ok.executor, 16, 16, 4, o, &st);
  EXPECT_EQ(st.sppDone, 4);
}

// A threshold every pixel meets at once ends the render after --min-spp samples: the image is
// then a plain 64-spp render's after its first 4 samples (its checkpoint), to the bit, and the
// stats say it converged.
TEST(AdaptiveSampling, WhenEveryPixelConvergesTheRenderEndsEarly) {
  Scene s;
  loadSmall("buddha", 16, &s);
  EmbreeAccel accel(s);
  Rendered early = renderWith(s, accel, 64, 1e6f, 4);
  RenderOptions o;
  o.progress = false;
  o.spp = 64;
  o.checkpointSeconds = 1e-12;  // every pass
  Image afterFour;
  o.checkpoint = [&](const Image& img, int done) {
    if (done == 4) afterFour = img;
  };
  RenderStats st;
  render(s, accel, o, &st);
  Rendered plain{afterFour, {}, {}, st};
  EXPECT_TRUE(early.stats.converged);
  EXPECT_FALSE(plain.stats.converged);
  EXPECT_EQ(early.stats.sppDone, 4);
  EXPECT_EQ(early.stats.pixelsStopped, 16u * 16u);
  EXPECT_EQ(early.stats.pixelSamples, uint64_t(16 * 16 * 4));
  ASSERT_EQ(early.img.rgb.size(), plain.img.rgb.size());
  EXPECT_EQ(0, std::memcmp(early.img.rgb.data(), plain.img.rgb.data(), plain.img.rgb.size() * sizeof(float)));
}

// Every integrator that samples pixel by pixel takes a threshold (the README's promise): path,
// direct, photon and grid, the last two through executors that wrap the camera pass and must
// pass its variance and mask on. Some pixels stop, the rest take every sample.
TEST(AdaptiveSampling, EveryPerPixelIntegratorTakesIt) {
  for (IntegratorType type : {IntegratorType::Path, IntegratorType::Direct, IntegratorType::Photon,
                              IntegratorType::Grid}) {
    Scene s;
    test::loadBundledSmall("buddha", 16, type, &s);
    s.integrator.photon.globalPhotons = s.integrator.photon.causticPhotons = 5000;
    test::useSmallGrid(s.integrator.grid);
    s.finalize();
    EmbreeAccel accel(s);
    Rendered r = renderWith(s, accel, 32, 0.05f, 4);
    EXPECT_GT(r.stats.pixelsStopped, 0u) << integratorName(type);
    EXPECT_LT(r.stats.pixelSamples, uint64_t(16 * 16 * 32)) << integratorName(type);
    EXPECT_EQ(r.stats.sppDone, 32) << integratorName(type) << ": the object's pixels are still noisy at 32";
  }
}
