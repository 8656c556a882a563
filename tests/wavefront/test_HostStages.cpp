// The wave stages as the CPU runs them, a wave a tile through their batch forms (HostStages.h),
// against the per-pixel body (renderPixel): each pixel adds the same samples in the same order,
// so over the GPU's BVH the sums agree to the bit; over Embree's packets, to float rounding.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <utility>

#include "accel/EmbreeAccel.h"
#include "support/SmallKernelScene.h"
#include "wavefront/HostStageLaunch.h"
#include "wavefront/WavePass.h"

using namespace envgi;
using test::Film;
using test::SmallScene;

namespace {

// Samples [s0, s1) of every pixel as the CPU executor takes them: a wave a tile of 16 (partial
// at the right and bottom), through the stages' batch forms.
template <class Integrator>
void renderTiles(const Camera& cam, const SampleSequence& seq, const Integrator& integ, int s0, int s1, FilmView film,
                 PixelCounters* counters) {
  HostWave wave(16 * 16, 16 * 16);
  HostStageLaunch launch = wave.launch();
  for (int y0 = 0; y0 < cam.height; y0 += 16)
    for (int x0 = 0; x0 < cam.width; x0 += 16) {
      const WaveRegion region{x0, y0, std::min(16, cam.width - x0), std::min(16, cam.height - y0)};
      runWavePass(launch, WaveContext<Integrator>{integ, cam, seq, film, region, wave.queues, wave.sums},
                  ShadeKindSet::all(), s0, s1, counters);
    }
}

// Samples [s0, s1) of every pixel twice: through renderPixel into a, and through renderTiles
// into b.
template <class Integrator>
void renderBothWays(const Camera& cam, const SampleSequence& seq, const Integrator& integ, int s0, int s1, Film* a,
                    Film* b, PixelCounters* ca, PixelCounters* cb) {
  for (int y = 0; y < cam.height; ++y)
    for (int x = 0; x < cam.width; ++x) renderPixel(cam, seq, integ, x, y, s0, s1, a->view(cam), ca);
  renderTiles(cam, seq, integ, s0, s1, b->view(cam), cb);
}

}  // namespace

// A wave a tile through the stages' batch forms against renderPixel: each pixel
// adds the same samples in the same order, so the sums agree to the bit, over whole and partial
// tiles (24 pixels in tiles of 16) and over two passes; for path, and for direct as the
// one-bounce path it is with one light and one BSDF sample (directAsPath).
TEST(HostStages, AddsTheSameSamplesAsRenderPixel) {
  for (std::string name : {"teapot-glass", "buddha", "cornell-box", "bunny-sunrise", "sun-and-sky"})
    for (IntegratorType type : {IntegratorType::Path, IntegratorType::Direct}) {
      SmallScene small(name, type);
      const KernelSettings& k = small.k;
      SampleIntegrator<BvhTracer> integ = small.integrator();
      ASSERT_TRUE(integ.shadesAfterTrace());
      const Camera& cam = small.scene.view().camera;
      size_t npix = size_t(cam.width) * cam.height;
      Film a{std::vector<Color>(npix, Color(0.f)), std::vector<double>(npix, 0.0)}, b = a;
      PixelCounters ca, cb;
      for (auto [s0, s1] : {std::pair{0, 3}, std::pair{3, 8}}) {
        renderBothWays(cam, k.sequence, integ, s0, s1, &a, &b, &ca, &cb);
        test::expectSameSums(a, b, ca, cb, type == IntegratorType::Path, name + " pass " + std::to_string(s0));
      }
      double mean = 0.0;
      for (const Color& c : a.sum) mean += c.x + c.y + c.z;
      EXPECT_GT(mean, 0.0) << name << ": an image, not a black film";
    }
}

// With the map hidden from the camera (hide_emitters), the camera rays that escape add nothing,
// whether they end in the camera round's lanes (pathAddEscape) or in renderPixel's pathShade;
// what the rays that hit see of the map is there, and the same to the bit.
TEST(HostStages, HiddenEmittersEscapeTheSameWayByBounce) {
  SmallScene small("buddha", IntegratorType::Path);
  small.k.path.hideEmitters = true;
  SampleIntegrator<BvhTracer> integ = small.integrator();
  ASSERT_EQ(small.k.sequence.type, SamplerType::Sobol) << "the camera round runs in lanes";
  const Camera& cam = small.scene.view().camera;
  const size_t npix = size_t(cam.width) * cam.height;
  Film a{std::vector<Color>(npix, Color(0.f)), std::vector<double>(npix, 0.0)}, b = a;
  PixelCounters ca, cb;
  renderBothWays(cam, small.k.sequence, integ, 0, 4, &a, &b, &ca, &cb);
  EXPECT_EQ(ca.rays, cb.rays);
  EXPECT_EQ(std::memcmp(a.sum.data(), b.sum.data(), npix * sizeof(Color)), 0);
  EXPECT_EQ(std::memcmp(a.sumSq.data(), b.sumSq.data(), npix * sizeof(double)), 0);
  int black = 0, lit = 0;
  for (const Color& c : a.sum) (c.x + c.y + c.z == 0.f ? black : lit)++;
  EXPECT_GT(black, int(npix / 4)) << "the background is hidden";
  EXPECT_GT(lit, 20) << "the buddha is lit by the map";
}

// direct runs by bounce where it is a one-bounce path (at most one light and one BSDF sample:
// the bundled scenes', the paper's and the study's settings), and per pixel with more, which
// trace several rays from one shading point.
TEST(HostStages, DirectRunsByBounceWithOneSampleOfEach) {
  SmallScene small("buddha", IntegratorType::Direct);
  SampleIntegrator<BvhTracer> integ = small.integrator();
  integ.direct.emitterSamples = integ.direct.bsdfSamples = 1;
  EXPECT_TRUE(integ.shadesAfterTrace());
  const PathParams p = integ.shadedPath();
  EXPECT_EQ(p.maxDepth, 2);
  EXPECT_EQ(p.envStrategy, integ.direct.envStrategy);
  EXPECT_GE(p.rrDepth, p.maxDepth) << "no roulette before the path ends";
  EXPECT_TRUE(p.lightSample && p.bsdfSample);
  for (auto [nE, nB] : {std::pair{1, 0}, std::pair{0, 1}}) {
    integ.direct.emitterSamples = nE, integ.direct.bsdfSamples = nB;
    EXPECT_TRUE(integ.shadesAfterTrace()) << nE << " " << nB;
    EXPECT_EQ(integ.shadedPath().lightSample, nE == 1);
    EXPECT_EQ(integ.shadedPath().bsdfSample, nB == 1);
  }
  for (auto [nE, nB] : {std::pair{2, 1}, std::pair{1, 2}, std::pair{2, 0}, std::pair{4, 4}}) {
    integ.direct.emitterSamples = nE, integ.direct.bsdfSamples = nB;
    EXPECT_FALSE(integ.shadesAfterTrace()) << nE << " " << nB;
  }
}

// The same sums as renderPixel's directTrace, to the bit over the GPU's BVH, with light samples
// only (the study's uniform, adaptive, importance, points) and with BSDF samples only (bsdf).
TEST(HostStages, DirectWithOneKindOfSampleByBounceAddsTheSameSamples) {
  for (std::string name : {"buddha", "cornell-box", "sun-and-sky", "teapot-glass"})
    for (auto [nE, nB] : {std::pair{1, 0}, std::pair{0, 1}}) {
      SmallScene small(name, IntegratorType::Direct);
      SampleIntegrator<BvhTracer> integ = small.integrator();
      integ.direct.emitterSamples = nE, integ.direct.bsdfSamples = nB;
      ASSERT_TRUE(integ.shadesAfterTrace());
      const KernelSettings& k = small.k;
      const Camera& cam = small.scene.view().camera;
      const size_t npix = size_t(cam.width) * cam.height;
      Film a{std::vector<Color>(npix, Color(0.f)), std::vector<double>(npix, 0.0)}, b = a;
      PixelCounters ca, cb;
      renderBothWays(cam, k.sequence, integ, 0, 8, &a, &b, &ca, &cb);
      const std::string what = name + " " + std::to_string(nE) + "+" + std::to_string(nB);
      EXPECT_LE(cb.rays, ca.rays) << what;
      EXPECT_GE(double(cb.rays), 0.99 * double(ca.rays)) << what;
      EXPECT_EQ(std::memcmp(a.sum.data(), b.sum.data(), npix * sizeof(Color)), 0) << what;
      double mean = 0.0;
      for (const Color& c : a.sum) mean += c.x + c.y + c.z;
      EXPECT_GT(mean, 0.0) << what << ": an image, not a black film";
    }
}

// The same over Embree, whose camera rays go through 16-wide packets in 4 x 4 blocks of pixels
// (whole tiles) or in row order (a tile whose side is not a multiple of 4: 22 pixels in tiles
// of 16 leaves 6), and whose bounce and shadow rays go through its stream calls. Embree's
// packets and streams find the same hits with t to an ulp or two, so the sums
// match renderPixel's to float rounding, except where a path's later choices turn on those
// bits (a mask's stochastic pass-through): there a pixel's samples differ, not its mean.
TEST(HostStages, OverEmbreePacketsAddsTheSameSamplesAsRenderPixel) {
  for (std::string name : {"buddha", "mask", "cornell-box"})
    for (int res : {24, 22}) {
      Scene scene;
      loadScene(std::string(ENVGI_SOURCE_DIR) + "/scenes/" + name + ".xml", {{"res", std::to_string(res)}}, scene);
      scene.camera.width = scene.camera.height = res;
      scene.integrator.type = IntegratorType::Path;
      scene.finalize();
      RenderOptions o;
      o.spp = 4;
      KernelSettings k = kernelSettings(scene, o);
      EmbreeAccel accel(scene);
      SampleIntegrator<EmbreeTracer> integ{k.type, k.path, k.direct, &scene.view(), EmbreeTracer{&accel}};
      const Camera& cam = scene.view().camera;
      size_t npix = size_t(cam.width) * cam.height;
      Film a{std::vector<Color>(npix, Color(0.f)), std::vector<double>(npix, 0.0)}, b = a;
      PixelCounters ca, cb;
      renderBothWays(cam, k.sequence, integ, 0, 4, &a, &b, &ca, &cb);
      // The mask's pass-through may turn a path another way, and with it its count of rays.
      EXPECT_NEAR(double(ca.rays), double(cb.rays), (name == "mask" ? 5e-3 : 1e-3) * double(ca.rays)) << name << " " << res;
      size_t same = 0;
      double meanA = 0.0, meanB = 0.0;
      for (size_t i = 0; i < npix; ++i) {
        bool close = true;
        for (int c = 0; c < 3; ++c) close = close && std::fabs(a.sum[i][c] - b.sum[i][c]) <= 1e-4f * (1.f + a.sum[i][c]);
        same += close;
        meanA += a.sum[i].x + a.sum[i].y + a.sum[i].z;
        meanB += b.sum[i].x + b.sum[i].y + b.sum[i].z;
      }
      // A mixed-up lane or block would move most pixels; float rounding moves none of them.
      EXPECT_GE(double(same), (name == "mask" ? 0.97 : 0.999) * double(npix)) << name << " " << res;
      EXPECT_NEAR(meanB, meanA, 0.01 * meanA) << name << " " << res;
      EXPECT_GT(meanA, 0.0) << name;
    }
}

// A region's pixel order (WaveRegion::at) visits each pixel once; with both sides multiples of
// 4, each 16 in a row are a 4 x 4 square (the camera's packets), else it goes row by row.
TEST(HostStages, RegionPixelsGoInBlocksOfFourByFour) {
  for (int tw : {4, 8, 16, 6})
    for (int th : {12, 4, 7}) {
      const WaveRegion region{0, 0, tw, th};
      const int n = tw * th;
      const bool blocks = tw % 4 == 0 && th % 4 == 0;
      EXPECT_EQ(region.inBlocks(), blocks);
      std::vector<int> count(size_t(n), 0), order;
      for (int k = 0; k < n; ++k) {
        int dx, dy;
        region.at(k, &dx, &dy);
        ASSERT_TRUE(dx >= 0 && dx < tw && dy >= 0 && dy < th) << tw << " x " << th << ", " << k;
        ++count[size_t(dy * tw + dx)];
        order.push_back(dy * tw + dx);
      }
      for (int k = 0; k < n; ++k) EXPECT_EQ(count[size_t(k)], 1) << tw << " x " << th << ", pixel " << k;
      for (size_t i = 0; i < order.size(); ++i) {
        if (blocks) {
          const int first = order[i - i % 16];
          EXPECT_EQ(order[i] % tw - first % tw, int(i % 4)) << tw << " x " << th;
          EXPECT_EQ(order[i] / tw - first / tw, int(i % 16 / 4)) << tw << " x " << th;
        } else {
          EXPECT_EQ(order[i], int(i)) << tw << " x " << th;
        }
      }
    }
}

// With a filter with negative lobes (Lanczos), the three bodies add the same weighted sums and
// the same sums of weights to the bit; the weights are not all one, some are negative, and the
// film's weighted mean of a pixel lies near its plain mean.
TEST(HostStages, EveryBodyAddsTheFiltersWeights) {
  SmallScene small("buddha", IntegratorType::Path);
  small.scene.camera.filter = makeFilter(FilterType::Lanczos);
  small.scene.finalize();
  const KernelSettings& k = small.k;
  SampleIntegrator<BvhTracer> integ = small.integrator();
  const Camera& cam = small.scene.view().camera;
  ASSERT_EQ(cam.filter.type, FilterType::Lanczos);
  size_t npix = size_t(cam.width) * cam.height;
  struct WeightedFilm {
    Film f;
    std::vector<float> w;
    FilmView view(const Camera& cam) {
      FilmView v = f.view(cam);
      v.weightSum = w.data();
      return v;
    }
  };
  WeightedFilm a{{std::vector<Color>(npix, Color(0.f)), std::vector<double>(npix, 0.0)}, std::vector<float>(npix, 0.f)};
  WeightedFilm b = a, c = a;
  PixelCounters ca, cb, cc;
  for (int y = 0; y < cam.height; ++y)
    for (int x = 0; x < cam.width; ++x) renderPixel(cam, k.sequence, integ, x, y, 0, 8, a.view(cam), &ca);
  uint64_t next = 0;
  regeneratePaths(cam, k.sequence, integ, 0, 8, b.view(cam), [&] { return next++; }, &cb);
  renderTiles(cam, k.sequence, integ, 0, 8, c.view(cam), &cc);
  EXPECT_EQ(std::memcmp(a.w.data(), b.w.data(), npix * sizeof(float)), 0);
  EXPECT_EQ(std::memcmp(a.w.data(), c.w.data(), npix * sizeof(float)), 0);
  EXPECT_EQ(std::memcmp(a.f.sum.data(), b.f.sum.data(), npix * sizeof(Color)), 0);
  EXPECT_EQ(std::memcmp(a.f.sum.data(), c.f.sum.data(), npix * sizeof(Color)), 0);
  double total = 0.0;
  size_t notEight = 0;
  for (float w : a.w) total += w, notEight += std::fabs(w - 8.f) > 1e-3f;
  EXPECT_GT(notEight, npix / 2) << "the weights are applied";
  EXPECT_NEAR(total / double(npix), 8.0, 0.5) << "and average one a sample";
  // filmMean divides by the weights' sum where it is at least a quarter of the count.
  FilmSums fs{a.f.sum, {}, a.w};
  Image img = filmMean(fs, cam.width, cam.height, 8);
  for (size_t i = 0; i < npix; ++i) {
    float d = a.w[i] > 2.f ? a.w[i] : 8.f;
    ASSERT_NEAR(img.rgb[3 * i + 1], a.f.sum[i].y / d, 1e-6f * (1.f + std::fabs(a.f.sum[i].y))) << i;
  }
}

// Adaptive sampling's mask: renderPixel, the CPU's waves and regeneratePaths leave a masked
// pixel's sums alone and give every other pixel the same sums to the bit as an unmasked pass.
TEST(HostStages, MaskedPixelsTakeNoSamplesAndTheRestTheSame) {
  SmallScene small("buddha", IntegratorType::Path);
  const KernelSettings& k = small.k;
  SampleIntegrator<BvhTracer> integ = small.integrator();
  const Camera& cam = small.scene.view().camera;
  size_t npix = size_t(cam.width) * cam.height;
  std::vector<unsigned char> mask(npix);
  for (size_t i = 0; i < npix; ++i) mask[i] = (i * 7919 % 5) < 2;  // two pixels in five sample
  Film full{std::vector<Color>(npix, Color(0.f)), std::vector<double>(npix, 0.0)};
  PixelCounters cf;
  for (int y = 0; y < cam.height; ++y)
    for (int x = 0; x < cam.width; ++x) renderPixel(cam, k.sequence, integ, x, y, 0, 4, full.view(cam), &cf);
  auto check = [&](Film& f, const char* body) {
    for (size_t i = 0; i < npix; ++i) {
      if (mask[i]) {
        EXPECT_EQ(std::memcmp(&f.sum[i], &full.sum[i], sizeof(Color)), 0) << body << " pixel " << i;
        EXPECT_EQ(f.sumSq[i], full.sumSq[i]) << body << " pixel " << i;
      } else {
        EXPECT_EQ(f.sum[i].x + f.sum[i].y + f.sum[i].z, 0.f) << body << " pixel " << i;
        EXPECT_EQ(f.sumSq[i], 0.0) << body << " pixel " << i;
      }
    }
  };
  auto masked = [&](Film& f) {
    FilmView v = f.view(cam);
    v.active = mask.data();
    return v;
  };
  Film a{std::vector<Color>(npix, Color(0.f)), std::vector<double>(npix, 0.0)}, b = a, c = a;
  PixelCounters ca, cb, cc;
  for (int y = 0; y < cam.height; ++y)
    for (int x = 0; x < cam.width; ++x) renderPixel(cam, k.sequence, integ, x, y, 0, 4, masked(a), &ca);
  check(a, "renderPixel");
  renderTiles(cam, k.sequence, integ, 0, 4, masked(b), &cb);
  check(b, "renderTiles");
  EXPECT_EQ(ca.rays, cb.rays);
  EXPECT_LT(ca.rays, cf.rays);
  uint64_t next = 0;
  regeneratePaths(cam, k.sequence, integ, 0, 4, masked(c), [&] { return next++; }, &cc);
  check(c, "regeneratePaths");
  EXPECT_EQ(ca.rays, cc.rays);
}
