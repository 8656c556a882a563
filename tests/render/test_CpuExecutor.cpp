// The GPU's kernel bodies and BVH, run by the CPU executor, render the same image in
// expectation as the Embree path: a per-region Z-test on the bundled scenes and on a glossy
// test scene, for path and direct.
#include <gtest/gtest.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cstdlib>
#include <filesystem>
#include <thread>
#include <tuple>
#if defined(__SANITIZE_ADDRESS__)
#include <sanitizer/lsan_interface.h>
#endif

#include "accel/Bvh.h"
#include "accel/EmbreeAccel.h"
#include "render/CpuExecutor.h"
#include "render/Progress.h"
#include "scene/SceneLoader.h"
#include "support/RegionZTest.h"
#include "support/ChiSquare.h"
#include "support/BundledScene.h"
#include "support/ImageAgreement.h"
#include "support/TestScenes.h"
#include "scene/NameTables.h"

using namespace envgi;

namespace {

struct Result {
  Image img;
  std::vector<float> var;
  RenderStats stats;
};

Result run(const Scene& s, CpuTracer tracer, int spp) {
  EmbreeAccel accel(s);
  RenderOptions o;
  o.progress = false;
  o.spp = spp;
  o.cpuTracer = tracer;
  Result r;
  o.varianceOut = &r.var;
  r.img = render(s, accel, o, &r.stats);
  EXPECT_EQ(r.stats.nonFiniteSamples, 0u);
  return r;
}

// A bundled scene at 32^2 with the given integrator (not yet finalized).
void loadSmall(const std::string& name, IntegratorType type, Scene* s) { test::loadBundledSmall(name, 32, type, s); }

// The same seed rendered with Embree and with the GPU's BVH, all passes done in both.
test::ImageAgreement embreeAgainstBvh(const Scene& s, int spp) {
  EmbreeAccel accel(s);
  RenderOptions o;
  o.progress = false;
  o.spp = spp;
  RenderStats sa, sb;
  Image a = render(s, accel, o, &sa);
  o.cpuTracer = CpuTracer::Bvh;
  Image b = render(s, accel, o, &sb);
  EXPECT_EQ(sa.sppDone, spp);
  EXPECT_EQ(sb.sppDone, spp);
  return test::compareImages(a, b);
}

}  // namespace

TEST(CpuExecutor, BvhKernelsMatchEmbreeOnBundledScenes) {
  for (std::string name : {"buddha", "cornell-box", "teapot-glass"}) {
    for (std::string integrator : {"path", "direct"}) {
      Scene s;
      loadScene(std::string(ENVGI_SOURCE_DIR) + "/scenes/" + name + ".xml", {{"res", "48"}}, s);
      s.camera.width = s.camera.height = 48;  // scenes without a res parameter too
      s.integrator.type = findIntegrator(integrator);
      if (integrator == "direct") s.integrator.env.strategy = "mis";
      s.sampler.seed = 3;
      s.finalize();
      Result a = run(s, CpuTracer::Embree, 32);
      s.sampler.seed = 4;  // independent estimates, so the Z-test's variances add
      Result b = run(s, CpuTracer::Bvh, 32);
      int regions = 0;
      double p = test::minRegionP(a.img, a.var, b.img, b.var, 8, &regions);
      EXPECT_GT(p, test::sidakAlpha(regions * 6)) << name << " " << integrator;
      double ma = 0, mb = 0;
      for (size_t i = 0; i < a.img.rgb.size(); ++i) {
        ma += a.img.rgb[i];
        mb += b.img.rgb[i];
      }
      EXPECT_NEAR(mb / ma, 1.0, 0.03) << name << " " << integrator;
      EXPECT_GT(b.stats.rays, 48u * 48u * 32u);
    }
  }
}

TEST(CpuExecutor, SameSeedSameImageUpToTraversalRounding) {
  Scene s;
  loadScene(std::string(ENVGI_SOURCE_DIR) + "/scenes/buddha.xml", {{"res", "32"}}, s);
  s.camera.width = s.camera.height = 32;
  s.finalize();
  Result a = run(s, CpuTracer::Embree, 8), b = run(s, CpuTracer::Bvh, 8);
  // The same samples: pixels differ only where two triangle tests round a hit differently.
  size_t same = 0;
  for (size_t i = 0; i < a.img.rgb.size(); ++i) same += std::fabs(a.img.rgb[i] - b.img.rgb[i]) <= 1e-3f * (1.f + a.img.rgb[i]);
  EXPECT_GT(double(same) / double(a.img.rgb.size()), 0.95);
}

// Instances as the GPU traverses them (two levels: a tree per group mesh, placed by each
// instance) against Embree's instancing, same seed: the same image up to traversal rounding,
// with path (the map and glossy bunnies) and sppm (photons through the instances).
TEST(CpuExecutor, InstancesOnTheBvhMatchEmbree) {
  for (IntegratorType type : {IntegratorType::Path, IntegratorType::Sppm}) {
    Scene s;
    loadSmall("instances", type, &s);
    s.integrator.sppm.photonCount = 20000;
    s.finalize();
    ASSERT_EQ(s.instances.size(), 10u);
    test::ImageAgreement ag = embreeAgainstBvh(s, 4);
    EXPECT_GT(ag.meanA, 0.0);
    EXPECT_NEAR(ag.meanRatio, 1.0, 0.01);
    EXPECT_GT(ag.sameShare, 0.9);
  }
}

// SPPM's steps as the GPU runs them (the envgi BVH) against Embree, with the same seed: the same
// visible points and photon paths, so the images agree up to traversal rounding.
TEST(CpuExecutor, SppmStepsOnTheBvhMatchEmbree) {
  for (std::string name : {"cornell-box", "teapot-glass"}) {
    Scene s;
    loadSmall(name, IntegratorType::Sppm, &s);
    s.integrator.sppm.photonCount = 20000;
    s.finalize();
    test::ImageAgreement ag = embreeAgainstBvh(s, 4);
    EXPECT_GT(ag.meanA, 0.0) << name;
    EXPECT_NEAR(ag.meanRatio, 1.0, 0.01) << name;
    EXPECT_GT(ag.sameShare, 0.9) << name;
  }
}

// The grid integrator's bodies as the GPU runs them (photon tracing, grid gather and camera
// samples over the envgi BVH) against Embree, same seed: the same photons and gather rays up to
// traversal rounding, so the images agree closely.
TEST(CpuExecutor, GridBodiesOnTheBvhMatchEmbree) {
  for (std::string name : {"cornell-box", "teapot-glass"}) {
    Scene s;
    loadSmall(name, IntegratorType::Grid, &s);
    s.integrator.grid.resolution = 12;
    s.integrator.grid.gatherRays = 32;
    s.integrator.grid.globalPhotons = 40000;
    s.integrator.grid.causticPhotons = 10000;
    s.finalize();
    test::ImageAgreement ag = embreeAgainstBvh(s, 8);
    EXPECT_GT(ag.meanA, 0.0) << name;
    EXPECT_NEAR(ag.meanRatio, 1.0, 0.01) << name;
    EXPECT_LT(ag.worstRegion, 0.03) << name;
  }
}

// The executor's per-thread tile batches must be visible to LeakSanitizer while it lives: held
// in TBB's scalable allocator (mmap'd, never scanned), their arrays read as leaks to any leak
// check made mid-render, as the viewer's fuzzer makes after an input while its session renders.
// Checked in the sanitizer build (CI's second suite); the release build has no LeakSanitizer.
TEST(CpuExecutor, ALeakCheckDuringARenderFindsNothing) {
#if defined(__SANITIZE_ADDRESS__)
  Scene s;
  loadSmall("buddha", IntegratorType::Path, &s);
  s.finalize();
  EmbreeAccel accel(s);
  RenderOptions o;
  o.progress = false;
  o.spp = 4;
  o.threads = 2;
  PreparedRender pr = prepareRender(s, accel, o);
  auto* cpu = dynamic_cast<CpuExecutor<SampleIntegrator<EmbreeTracer>>*>(pr.executor.get());
  ASSERT_TRUE(cpu && cpu->runsInWaves()) << "the path that keeps a wave a thread";
  Progress quiet(1, false);
  PassCounters counters;
  pr.executor->runPass(0, 4, quiet, &counters);
  EXPECT_EQ(__lsan_do_recoverable_leak_check(), 0) << "memory the live executor holds was reported as leaked";
#else
  GTEST_SKIP() << "needs LeakSanitizer: runs in the sanitizer build (.ci/run's second suite)";
#endif
}

// Ctrl-C inside a pass (PassExecutor::watchCancel): no tile starts once it is set, a started
// tile runs whole, and cutPass() names the pixels that took the pass; the others keep their
// film as it was. Set before the pass, nothing runs; unwatched, the pass runs whole.
TEST(CpuExecutor, CtrlCCutsAPassBetweenTiles) {
  auto same = [](const Color& a, const Color& b) { return a.x == b.x && a.y == b.y && a.z == b.z; };
  Scene s;
  test::loadBundledSmall("buddha", 128, IntegratorType::Path, &s);
  s.finalize();
  EmbreeAccel accel(s);
  RenderOptions o;
  o.progress = false;
  o.threads = 2;
  PreparedRender pr = prepareRender(s, accel, o);
  PassExecutor& ex = *pr.executor;
  Progress quiet(1, false);
  PassCounters counters;
  std::atomic<bool> cancel{true};
  ex.runPass(0, 1, quiet, &counters);  // not watched: whole, though cancel is set
  EXPECT_EQ(ex.cutPass(), nullptr);
  FilmSums before, after;
  ex.readFilm(&before);
  size_t lit = 0;
  for (const Color& c : before.sum) lit += c.x + c.y + c.z > 0.f;
  EXPECT_GT(lit, before.sum.size() * 9 / 10) << "the first pass missed pixels";

  ex.watchCancel(&cancel);
  ex.runPass(1, 2, quiet, &counters);  // set before the pass: no tile runs
  ASSERT_NE(ex.cutPass(), nullptr);
  for (unsigned char t : *ex.cutPass()) ASSERT_EQ(t, 0);
  ex.readFilm(&after);
  for (size_t i = 0; i < after.sum.size(); ++i) ASSERT_TRUE(same(after.sum[i], before.sum[i])) << i;

  // Set while the pass runs (1M samples: a second or more on two cores).
  cancel = false;
  std::thread ctrlC([&] {
    std::this_thread::sleep_for(std::chrono::milliseconds(60));
    cancel = true;
  });
  ex.runPass(1, 65, quiet, &counters);
  ctrlC.join();
  const std::vector<unsigned char>* took = ex.cutPass();
  ASSERT_NE(took, nullptr) << "the pass ended before Ctrl-C";
  ex.readFilm(&after);
  size_t ran = 0;
  for (int y = 0; y < 128; ++y)
    for (int x = 0; x < 128; ++x) {
      const size_t i = size_t(y) * 128 + size_t(x);
      ran += (*took)[i];
      // Whole tiles of 16 x 16: a pixel took the pass as its tile's corner did.
      ASSERT_EQ((*took)[i], (*took)[size_t(y / 16 * 16) * 128 + size_t(x / 16 * 16)]) << x << ", " << y;
      if (!(*took)[i]) {
        ASSERT_TRUE(same(after.sum[i], before.sum[i])) << x << ", " << y;
      }
    }
  EXPECT_GT(ran, 0u);
  EXPECT_LT(ran, size_t(128 * 128));
  size_t changed = 0;
  for (size_t i = 0; i < after.sum.size(); ++i) changed += !same(after.sum[i], before.sum[i]);
  EXPECT_LE(changed, ran);
  EXPECT_GT(changed, ran * 9 / 10) << "the pixels of the tiles that ran took their samples";

  ex.watchCancel(nullptr);
  ex.runPass(65, 66, quiet, &counters);
  EXPECT_EQ(ex.cutPass(), nullptr);
}

// The executor a render gets runs direct in waves with any count of samples (as a one-bounce
// path with at most one light and one BSDF sample, whole in one stage with more; renderPixel
// only where ENVGI_CPU_BY_BOUNCE=0 asks), and names the device alone either way.
TEST(CpuExecutor, DirectRunsInWavesWithAnyCountOfSamples) {
  for (auto [nE, nB] : {std::pair{1, 1}, std::pair{1, 0}, std::pair{0, 1}, std::pair{2, 1}, std::pair{1, 3}}) {
    Scene s;
    loadSmall("buddha", IntegratorType::Direct, &s);
    s.integrator.direct.emitterSamples = nE;
    s.integrator.direct.bsdfSamples = nB;
    s.finalize();
    EmbreeAccel accel(s);
    RenderOptions o;
    o.progress = false;
    o.spp = 2;
    PreparedRender pr = prepareRender(s, accel, o);
    auto* cpu = dynamic_cast<CpuExecutor<SampleIntegrator<EmbreeTracer>>*>(pr.executor.get());
    ASSERT_NE(cpu, nullptr);
    EXPECT_TRUE(cpu->runsInWaves()) << nE << " + " << nB;
    EXPECT_EQ(cpu->deviceName(), "cpu");
  }
}

// The CPU's waves against renderPixel on every bundled scene, for path and for direct with the
// scene's strategy: independent seeds and a per-region Z-test, as Mitsuba's render tests do.
// WaveStages.* and HostStages.* hold the two to the bit over the GPU's BVH; this holds them
// over Embree, whose packets round the camera's hits their own way.
TEST(CpuExecutor, WavesAgreeWithRenderPixelOnEveryBundledScene) {
  std::vector<std::string> names;
  for (const auto& e : std::filesystem::directory_iterator(std::string(ENVGI_SOURCE_DIR) + "/scenes"))
    if (e.path().extension() == ".xml") names.push_back(e.path().stem().string());
  std::sort(names.begin(), names.end());
  ASSERT_GE(names.size(), 15u);
  const int tests = int(names.size()) * 2;
  for (const std::string& name : names)
    for (IntegratorType type : {IntegratorType::Path, IntegratorType::Direct}) {
      const std::string what = name + (type == IntegratorType::Path ? " path" : " direct");
      Scene s;
      loadSmall(name, type, &s);
      s.sampler.seed = 5;
      s.finalize();
      Result a = run(s, CpuTracer::Embree, 32);
      setenv("ENVGI_CPU_BY_BOUNCE", "0", 1);
      {
        EmbreeAccel accel(s);
        RenderOptions o;
        o.progress = false;
        PreparedRender pr = prepareRender(s, accel, o);
        auto* cpu = dynamic_cast<CpuExecutor<SampleIntegrator<EmbreeTracer>>*>(pr.executor.get());
        EXPECT_TRUE(cpu && !cpu->runsInWaves()) << what << ": renderPixel a sample at a time";
      }
      s.sampler.seed = 6;
      Result b = run(s, CpuTracer::Embree, 32);
      unsetenv("ENVGI_CPU_BY_BOUNCE");
      int regions = 0;
      const double p = test::minRegionP(a.img, a.var, b.img, b.var, 8, &regions);
      EXPECT_GT(p, test::sidakAlpha(tests * regions)) << what;
      double ma = 0.0;
      for (float v : a.img.rgb) ma += v;
      EXPECT_GT(ma, 0.0) << what << ": an image, not a black film";
    }
}
