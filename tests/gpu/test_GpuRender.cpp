// The CUDA executor against the CPU: per-region Z-tests of GPU images against CPU images on
// the bundled scenes, for path and direct with every environment strategy. Exits 77 (ctest:
// skipped) where there is no CUDA device; the build alone proves the kernels compile.
#include <gtest/gtest.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstdlib>
#include <cstdio>
#include <filesystem>
#include <unistd.h>
#include <tuple>
#include <utility>

#include "accel/Bvh.h"
#include "accel/EmbreeAccel.h"
#include "gpu/CudaExecutor.h"
#include "gpu/GpuSceneFiles.h"
#include "render/PhotonShooter.h"
#include "render/Renderer.h"
#include "render/SppmPassExecutor.h"
#include "scene/NameTables.h"
#include "scene/SceneLoader.h"
#include "support/ImageAgreement.h"
#include "support/RegionZTest.h"
#include "image/Image.h"
#include "view/ViewSessionProbe.h"

using namespace envgi;
using json = nlohmann::json;

namespace {

constexpr int kRes = 64;

struct Result {
  Image img;
  std::vector<float> var;
  RenderStats stats;
};

Result renderOn(bool cuda, const Scene& s, int spp) {
  RenderOptions o;
  o.progress = false;
  o.spp = spp;
  Result r;
  o.varianceOut = &r.var;
  if (cuda) {
    Bvh bvh(s);
    auto ex = gpu::makeCudaExecutor(s, bvh, kernelSettings(s, o), 0, true);
    r.img = renderPasses(*ex, s.camera.width, s.camera.height, spp, o, &r.stats);
  } else {
    EmbreeAccel accel(s);
    r.img = render(s, accel, o, &r.stats);
  }
  return r;
}


// A bundled scene at kRes^2 with the given integrator (not yet finalized).
void loadBundled(const std::string& name, IntegratorType type, Scene* s) {
  loadScene(test::bundledScenesDir() + "/" + name + ".xml", {}, *s);
  s->camera.width = s->camera.height = kRes;
  s->integrator.type = type;
}

RenderOptions quietOptions(int spp) {
  RenderOptions o;
  o.progress = false;
  o.spp = spp;
  return o;
}

Image renderOnCpu(const Scene& s, const RenderOptions& o, RenderStats* st) {
  EmbreeAccel accel(s);
  return render(s, accel, o, st);
}

struct Case {
  std::string scene, integrator, strategy;
  float aperture = 0.f;  // > 0: seen through a thin lens focused at 6.1
  bool spot = false;     // the point lights become spots aimed at the origin
};

// Turns each point light into a spot aimed at the origin (cutoff 30 degrees, beam 20), so that
// the cone's edge and its linear falloff cross the image.
void pointLightsToSpots(Scene* s) {
  for (DeltaLight& l : s->deltaLights) {
    if (!l.point) continue;
    l.axis = normalize(-l.v);
    setSpotCone(l, 30.f * kPi / 180.f, 20.f * kPi / 180.f);
  }
}

}  // namespace

TEST(GpuRender, ZTestAgainstCpuOnBundledScenes) {
  std::vector<Case> cases;
  for (std::string sc : {"buddha", "cornell-box", "teapot-glass", "textured", "microfacets", "brushed", "sun-and-sky", "normal-map", "principled", "mask", "orthographic", "blend", "instances", "textured-light"})
    cases.push_back({sc, "path", "mis"});
  cases.push_back({"textured", "path", "mis", 0.2f});
  cases.push_back({"sun-and-sky", "path", "mis", 0.f, true});
  for (std::string st : {"uniform", "cosine", "bsdf", "importance", "alias", "adaptive", "mis", "product"})
    cases.push_back({"buddha", "direct", st});
  const int region = 8, regionsPerCase = (kRes / region) * (kRes / region);
  const double alpha = 1.0 - std::pow(0.99, 1.0 / double(regionsPerCase * cases.size()));
  for (const Case& c : cases) {
    Scene s;
    loadScene(test::bundledScenesDir() + "/" + c.scene + ".xml", {}, s);
    s.camera.width = s.camera.height = kRes;
    s.integrator.type = findIntegrator(c.integrator);
    s.integrator.env.strategy = c.strategy;
    s.camera.apertureRadius = c.aperture;
    s.camera.focusDistance = 6.1f;
    if (c.spot) pointLightsToSpots(&s);
    s.sampler.seed = 1;
    s.finalize();
    Result cpu = renderOn(false, s, 128);
    s.sampler.seed = 2;
    Result gpu = renderOn(true, s, 128);
    int regions = 0;
    double p = test::minRegionP(cpu.img, cpu.var, gpu.img, gpu.var, region, &regions);
    double mc = 0, mg = 0;
    for (size_t i = 0; i < cpu.img.rgb.size(); ++i) {
      mc += cpu.img.rgb[i];
      mg += gpu.img.rgb[i];
    }
    std::printf("%-12s %-6s %-10s %s%s min p %.3g (alpha %.2g), image mean GPU/CPU %.4f, %.1f vs %.1f Mrays/s\n",
                c.scene.c_str(), c.integrator.c_str(), c.strategy.c_str(), c.aperture > 0.f ? "lens" : "", c.spot ? "spot" : "", p, alpha, mg / mc,
                gpu.stats.raysPerSecond() / 1e6, cpu.stats.raysPerSecond() / 1e6);
    EXPECT_GT(p, alpha) << c.scene << " " << c.integrator << " " << c.strategy;
    EXPECT_EQ(gpu.stats.nonFiniteSamples, 0u);
    EXPECT_EQ(gpu.stats.sppDone, 128);
  }
}

// SPPM's kernels against the CPU driver with the same seed: the same visible points and photon
// paths, up to traversal rounding, FMA contraction and the order of the atomics' float sums;
// so the image means and the 8x8-region means agree closely.
TEST(GpuRender, SppmMatchesTheCpuDriver) {
  for (std::string name : {"cornell-box", "teapot-glass", "buddha", "sun-and-sky", "mask"}) {
    Scene s;
    loadBundled(name, IntegratorType::Sppm, &s);
    s.integrator.sppm.photonCount = 200000;
    s.finalize();
    RenderOptions o = quietOptions(16);
    RenderStats cs, gs;
    Image cpu = renderOnCpu(s, o, &cs);
    Bvh bvh(s);
    auto ex = gpu::makeCudaSppmExecutor(s, bvh, sppmParams(s), makePhotonEmitter(s), 0);
    Image gpuImg = renderPasses(*ex, kRes, kRes, 16, o, &gs);
    EXPECT_EQ(gs.sppDone, 16);
    test::ImageAgreement ag = test::compareImages(cpu, gpuImg);
    SppmStats st = dynamic_cast<SppmPassExecutor&>(*ex).stats();
    std::printf("%-12s sppm: image mean GPU/CPU %.4f, worst region %.3f, GPU %.1f ms a pass (%.2f s photons), "
                "CPU %.1f ms a pass\n",
                name.c_str(), ag.meanRatio, ag.worstRegion, 1e3 * gs.seconds / 16, st.photonSeconds,
                1e3 * cs.seconds / 16);
    EXPECT_NEAR(ag.meanRatio, 1.0, 0.01) << name;
    EXPECT_LT(ag.worstRegion, 0.05) << name;
  }
}

// The photon-map pass on the GPU against the CPU's, same seed: the same photons up to traversal
// rounding, so the counts, the stored power and its spatial histogram (8^3 cells over the
// scene's bounds) agree closely.
TEST(GpuRender, PhotonMapsMatchTheCpu) {
  for (std::string name : {"cornell-box", "teapot-glass", "buddha", "sun-and-sky", "mask"}) {
    Scene s;
    loadScene(test::bundledScenesDir() + "/" + name + ".xml", {}, s);
    s.finalize();
    EmbreeAccel accel(s);
    Bvh bvh(s);
    PhotonShootSettings ps;
    ps.globalPhotons = 500000;
    ps.causticPhotons = 200000;
    ps.progress = false;
    PhotonMap cg, cc, gg, gc;
    PhotonShootStats cs, gs;
    shootPhotons(s, accel, ps, &cg, &cc, &cs);
    ps.tracer = gpu::makeCudaPhotonTracer(s, bvh, 0, ps.maxDepth);
    shootPhotons(s, accel, ps, &gg, &gc, &gs);
    std::printf("%-12s photons: CPU %.2f s, GPU %.2f s tracing (%llu + %llu emitted)\n", name.c_str(),
                cs.traceSeconds, gs.traceSeconds, (unsigned long long)gs.emittedGlobal,
                (unsigned long long)gs.emittedCaustic);
    const SceneView& sc = s.view();
    auto histogram = [&](const PhotonMap& m) {
      std::vector<double> h(512, 0.0);
      Vec3f ext = sc.boundsMax - sc.boundsMin;
      for (const Photon& p : m.photons()) {
        int c[3];
        for (int a = 0; a < 3; ++a)
          c[a] = std::clamp(int(8.f * (p.p[a] - sc.boundsMin[a]) / std::max(ext[a], 1e-6f)), 0, 7);
        h[size_t(c[0] + 8 * (c[1] + 8 * c[2]))] += luminance(p.power);
      }
      return h;
    };
    for (auto [cpu, gpuMap, what] : {std::tuple{&cg, &gg, "global"}, std::tuple{&cc, &gc, "caustic"}}) {
      if (cpu->size() == 0) continue;
      EXPECT_NEAR(double(gpuMap->size()) / double(cpu->size()), 1.0, 0.005) << name << " " << what;
      std::vector<double> a = histogram(*cpu), b = histogram(*gpuMap);
      double total = 0.0, totalB = 0.0;
      for (size_t i = 0; i < a.size(); ++i) {
        total += a[i];
        totalB += b[i];
      }
      EXPECT_NEAR(totalB / total, 1.0, 0.005) << name << " " << what;
      for (size_t i = 0; i < a.size(); ++i)
        if (a[i] > 0.01 * total) {
          EXPECT_NEAR(b[i] / a[i], 1.0, 0.03) << name << " " << what << " cell " << i;
        }
    }
  }
}

// The grid integrator on the GPU (photons, grid fill and camera passes) against the CPU's,
// same seed: the same photons, gather rays and camera samples up to traversal rounding.
TEST(GpuRender, GridMatchesTheCpu) {
  for (std::string name : {"cornell-box", "teapot-glass", "buddha", "sun-and-sky"}) {
    Scene s;
    loadBundled(name, IntegratorType::Grid, &s);
    s.finalize();
    RenderOptions o = quietOptions(16);
    RenderStats cs, gs;
    Image cpu = renderOnCpu(s, o, &cs);
    Bvh bvh(s);
    SequenceAndSpp q = gridSequence(s, o);
    auto ex = gpu::makeCudaGridExecutor(s, bvh, gridExecutorSettings(s, o), q.sequence, 0, false);
    Image gpuImg = renderPasses(*ex, kRes, kRes, q.spp, o, &gs);
    test::ImageAgreement ag = test::compareImages(cpu, gpuImg);
    std::printf("%-12s grid: image mean GPU/CPU %.4f, worst region %.3f\n", name.c_str(), ag.meanRatio, ag.worstRegion);
    EXPECT_NEAR(ag.meanRatio, 1.0, 0.01) << name;
    EXPECT_LT(ag.worstRegion, 0.05) << name;
    EXPECT_EQ(gs.nonFiniteSamples, 0u);
  }
}

// The paper's basis (M directions a point) on the GPU, through prepareCudaRender as the CLI
// reaches it, against the CPU's DirectionalGridExecutor with the same seed.
TEST(GpuRender, DirectionalGridMatchesTheCpu) {
  for (std::string name : {"cornell-box", "buddha"}) {
    Scene s;
    loadBundled(name, IntegratorType::Grid, &s);
    s.integrator.grid.basis = "directions";
    s.integrator.grid.directions = 32;
    s.finalize();
    RenderOptions o = quietOptions(16);
    RenderStats cs, gs;
    Image cpu = renderOnCpu(s, o, &cs);
    Bvh bvh(s);
    PreparedRender pr = gpu::prepareCudaRender(s, bvh, nullptr, o, 0, nullptr);
    Image gpuImg = renderPasses(*pr.executor, kRes, kRes, pr.spp, o, &gs);
    test::ImageAgreement ag = test::compareImages(cpu, gpuImg);
    std::printf("%-12s grid (directions): image mean GPU/CPU %.4f, worst region %.3f\n", name.c_str(), ag.meanRatio,
                ag.worstRegion);
    EXPECT_NEAR(ag.meanRatio, 1.0, 0.01) << name;
    EXPECT_LT(ag.worstRegion, 0.05) << name;
    EXPECT_EQ(gs.nonFiniteSamples, 0u);
  }
}

// Two GPU executors of the same scene, made under the environment settings `setA` and `setB`
// (NAME=VALUE, or "" for none), render 32 spp: the same rays, and images whose largest relative
// difference stays below 1e-3 (a sample lost or doubled of 32 is 3%). Returns the two executors'
// device names, checked by the caller.
std::pair<std::string, std::string> expectSameSamples(const std::string& name, IntegratorType type, const char* setA,
                                                      const char* setB, const char* what) {
  Scene s;
  loadBundled(name, type, &s);
  s.finalize();
  Bvh bvh(s);
  RenderOptions o = quietOptions(32);
  auto make = [&](const char* set) {
    std::string nv = set;
    const size_t eq = nv.find('=');
    if (eq != std::string::npos) setenv(nv.substr(0, eq).c_str(), nv.substr(eq + 1).c_str(), 1);
    auto ex = gpu::makeCudaExecutor(s, bvh, kernelSettings(s, o), 0, false);
    if (eq != std::string::npos) unsetenv(nv.substr(0, eq).c_str());
    return ex;
  };
  auto a = make(setA), b = make(setB);
  RenderStats sa, sb;
  Image ia = renderPasses(*a, kRes, kRes, 32, o, &sa), ib = renderPasses(*b, kRes, kRes, 32, o, &sb);
  EXPECT_EQ(sa.rays, sb.rays) << name;
  EXPECT_EQ(sb.sppDone, 32);
  double worst = 0.0;
  for (size_t i = 0; i < ia.rgb.size(); ++i)
    worst = std::max(worst, double(std::fabs(ia.rgb[i] - ib.rgb[i])) / (1e-3 + std::fabs(ia.rgb[i])));
  std::printf("%-12s %-6s %s: largest relative difference %.2g, %.1f vs %.1f Mrays/s\n", name.c_str(),
              type == IntegratorType::Path ? "path" : "direct", what, worst, sb.raysPerSecond() / 1e6,
              sa.raysPerSecond() / 1e6);
  EXPECT_LT(worst, 1e-3) << name;
  return {a->deviceName(), b->deviceName()};
}

// Path regeneration (the default; ENVGI_GPU_REGEN=0 turns it off) draws the same samples as one
// thread a pixel, so the same seed gives the same image up to the order in which the atomics
// add a pixel's samples (largest relative difference measured on an H200: 8.7e-5).
TEST(GpuRender, RegenerationMatchesOneThreadAPixel) {
  for (std::string name : {"buddha", "teapot-glass", "cornell-box"})
    for (IntegratorType type : {IntegratorType::Path, IntegratorType::Direct}) {
      auto [a, b] = expectSameSamples(name, type, "ENVGI_GPU_REGEN=0", "", "regeneration against one thread a pixel");
      EXPECT_EQ(a.find("regeneration"), std::string::npos) << a;
      EXPECT_NE(b.find("regeneration"), std::string::npos) << b;
    }
}

// The stages (ENVGI_GPU_STAGES=1: a kernel a stage, hits shaded by material kind; =wide: the
// shade kernels at up to 128 registers) draw the same samples as path regeneration: the same
// rays, and the same image up to the order of regeneration's atomic adds.
TEST(GpuRender, StagesMatchRegeneration) {
  for (std::string name : {"buddha", "teapot-glass", "cornell-box", "bunny-sunrise"})
    for (IntegratorType type : {IntegratorType::Path, IntegratorType::Direct})
      for (std::string stages : {"1", "wide"}) {
        const std::string set = "ENVGI_GPU_STAGES=" + stages;
        auto [a, b] = expectSameSamples(name, type, "", set.c_str(), "stages against regeneration");
        EXPECT_NE(b.find(stages == "wide" ? "stages, wide shading" : "stages)"), std::string::npos) << b;
      }
}

// Adaptive sampling on the GPU: the mask reaches the regeneration kernel, so pixels stop at pass
// ends with their noise below the threshold, fewer samples are taken, and the image's mean
// agrees with the CPU's adaptive render.
TEST(GpuRender, AdaptiveSamplingStopsConvergedPixels) {
  Scene s;
  loadBundled("buddha", IntegratorType::Path, &s);
  s.finalize();
  Bvh bvh(s);
  RenderOptions o = quietOptions(64);
  o.noiseThreshold = 0.05f;
  o.adaptiveMinSpp = 8;
  std::vector<float> var;
  std::vector<int> samples, cpuSamples;
  o.varianceOut = &var;
  o.samplesOut = &samples;
  // As `render` makes it (prepareCudaRender), so that the executor keeps the variance it needs.
  PreparedRender pr = gpu::prepareCudaRender(s, bvh, nullptr, o, 0, nullptr);
  RenderStats st, cst;
  Image img = renderPasses(*pr.executor, kRes, kRes, 64, o, &st);
  ASSERT_EQ(samples.size(), size_t(kRes) * kRes);
  uint64_t taken = 0;
  for (size_t i = 0; i < samples.size(); ++i) {
    taken += uint64_t(samples[i]);
    EXPECT_TRUE(samples[i] == 8 || samples[i] == 16 || samples[i] == 32 || samples[i] == 64) << samples[i];
    if (samples[i] == 64) continue;
    float lum = luminance(img.rgb[3 * i], img.rgb[3 * i + 1], img.rgb[3 * i + 2]);
    double noise = std::sqrt(double(var[i])) / (1e-4 + std::sqrt(std::max(0.0, double(lum))));
    EXPECT_LT(noise, 0.05 * 1.001) << "pixel " << i;
  }
  EXPECT_EQ(taken, st.pixelSamples);
  EXPECT_GT(st.pixelsStopped, 0u);
  EXPECT_LT(taken, uint64_t(kRes) * kRes * 64 * 3 / 4);
  o.varianceOut = nullptr;
  o.samplesOut = &cpuSamples;
  Image cpu = renderOnCpu(s, o, &cst);
  test::ImageAgreement a = test::compareImages(cpu, img);
  std::printf("adaptive on the GPU: %.1f%% of the samples (CPU %.1f%%), mean ratio to the CPU's %.4f\n",
              100.0 * double(st.pixelSamples) / (double(kRes) * kRes * 64),
              100.0 * double(cst.pixelSamples) / (double(kRes) * kRes * 64), a.meanRatio);
  EXPECT_NEAR(a.meanRatio, 1.0, 0.02);
}

// The viewer on the GPU (`envgi view --device cuda --noise-threshold`): the session makes its
// executor through the GPU's preparer, pixels stop once converged, and the image divides each
// by its own samples, so its mean agrees with the same session's full render.
TEST(GpuRender, ViewerRefinesAdaptivelyOnTheDevice) {
  namespace fs = std::filesystem;
  fs::path dir = fs::temp_directory_path() / ("envgi_gpu_view_" + std::to_string(::getpid()));
  fs::create_directories(dir);
  test::Sink sink;
  ViewOptions vo;
  vo.noiseThreshold = 0.1f;
  vo.adaptiveMinSpp = 4;
  auto calls = std::make_shared<std::atomic<int>>(0);
  vo.prepare = [calls, cuda = gpu::cudaPreparer(0)](const Scene& sc, const EmbreeAccel& a, const RenderOptions& o) {
    ++*calls;
    return cuda(sc, a, o);
  };
  auto session = test::makeSession(dir.string(), sink, vo, 256);
  json done = test::frameWhere(*session, sink, [](const json& f) { return f["converged"] == true; });
  ASSERT_FALSE(done.is_null());
  EXPECT_EQ(calls->load(), 1) << "the session's executor came from the GPU's preparer";
  EXPECT_LT(done["spp"].get<int>(), 256);
  EXPECT_GE(done["meanSpp"].get<double>(), 4.0);
  EXPECT_LT(done["meanSpp"].get<double>(), done["spp"].get<double>());
  Image early = loadImage(json::parse(session->handle(R"({"type":"save"})"))["path"]);
  session->handle(R"({"type":"adaptive","threshold":0})");
  json full = test::frameWhere(*session, sink, [](const json& f) { return f["spp"] == 256 && f["adaptive"] == false; });
  ASSERT_FALSE(full.is_null());
  Image ref = loadImage(json::parse(session->handle(R"({"type":"save"})"))["path"]);
  std::printf("viewer on the GPU: converged at %d passes, mean %.1f spp; image mean %.4f against %.4f at 256\n",
              done["spp"].get<int>(), done["meanSpp"].get<double>(), test::meanOfImage(early), test::meanOfImage(ref));
  EXPECT_NEAR(test::meanOfImage(early), test::meanOfImage(ref), 0.05 * test::meanOfImage(ref));
  session->stop();
  fs::remove_all(dir);
}

// Without machine code for the device, every program start spends seconds in the driver's
// PTX JIT (a build for sm_75 took 7-10 s a start on an H200).
TEST(GpuRender, BuildHasMachineCodeForTheDevice) {
  auto [major, minor] = gpu::computeCapability(0);
  EXPECT_TRUE(gpu::hasMachineCodeFor(major, minor)) << "sm_" << major << minor;
  EXPECT_FALSE(gpu::hasMachineCodeFor(7, 5));
}

// The path kernel's registers decide how many paths an SM keeps in flight. Copying each hit's
// material whole (textures) took it from 117 to 179 registers on sm_90, from 4 blocks
// an SM to 3; reading it in place took an H200 from 336 to 405 M samples/s. Nothing else noticed.
TEST(GpuRender, PathKernelKeepsItsOccupancy) {
  gpu::KernelOccupancy o = gpu::pathKernelOccupancy(0);
  std::printf("path kernel: %d registers a thread, %d blocks of %d an SM\n", o.registers, o.blocksPerSM,
              o.threadsPerBlock);
  EXPECT_GE(o.blocksPerSM * o.threadsPerBlock, gpu::kTracingThreadsPerSM) << o.registers << " registers a thread";
}

TEST(GpuRender, BadDeviceIndexIsAnError) {
  Scene s;
  loadScene(test::bundledScenesDir() + "/cornell-box.xml", {}, s);
  s.finalize();
  Bvh bvh(s);
  RenderOptions o;
  EXPECT_THROW(gpu::makeCudaExecutor(s, bvh, kernelSettings(s, o), 1000, false), std::runtime_error);
  EXPECT_THROW(gpu::makeCudaSppmExecutor(s, bvh, sppmParams(s), makePhotonEmitter(s), 1000), std::runtime_error);
}

int main(int argc, char** argv) {
  std::string why;
  if (gpu::deviceCount(&why) == 0) {
    std::printf("envgi_gpu_tests: skipped, no CUDA device (%s)\n", why.c_str());
    return 77;
  }
  std::printf("envgi_gpu_tests: on %s\n", gpu::deviceName(0).c_str());
  ::testing::InitGoogleTest(&argc, argv);
  return RUN_ALL_TESTS();
}
