#include "render/Renderer.h"

#include <spdlog/spdlog.h>

#include <chrono>
#include <cstdio>
#include <mutex>
#include <stdexcept>

#include "accel/Bvh.h"
#include "render/CpuExecutor.h"
#include "integrators/PhotonIntegrator.h"
#include "render/SppmExecutor.h"
#include "scene/StrategyNames.h"
#include "photon/PhotonShooter.h"

namespace envgi {

namespace {

using Clock = std::chrono::steady_clock;

EnvStrategy strategyOf(const std::string& s) { return findStrategy(s).env; }

void logPhotonStats(const PhotonShootStats& st) {
  spdlog::info("photon pass: {} global photons stored ({} emitted), {} caustic ({} emitted), {:.2f} s tracing, "
               "{:.2f} s building kd-trees, {:.1f} MB ({} bytes a photon)",
               st.storedGlobal, st.emittedGlobal, st.storedCaustic, st.emittedCaustic, st.traceSeconds,
               st.buildSeconds, st.bytes / 1e6,
               st.storedGlobal + st.storedCaustic > 0 ? st.bytes / (st.storedGlobal + st.storedCaustic) : 0);
}

Image renderSppm(const Scene& scene, const EmbreeAccel& accel, const RenderOptions& opts, RenderStats* stats) {
  const IntegratorSettings& is = scene.integrator;
  SppmParams sp;
  sp.photonsPerPass = is.photonCount;
  sp.initialRadius = is.initialRadius;
  sp.alpha = is.alpha;
  sp.maxDepth = is.maxDepth > 0 ? is.maxDepth : 16;
  sp.seed = scene.sampler.seed;
  sp.strategy = strategyOf(is.strategy);
  int passes = opts.spp > 0 ? opts.spp : is.passes;
  if (passes <= 0) throw std::runtime_error("sppm: passes must be positive");
  SppmExecutor ex(scene, accel, sp, opts.threads);
  Image img = renderPasses(ex, scene.view().camera.width, scene.view().camera.height, passes, opts, stats);
  SppmStats st = ex.stats();
  spdlog::info("sppm: {} passes, {} photons ({} photon-visible-point hits), camera passes {:.2f} s, photon passes "
               "{:.2f} s, mean final radius {:.4g}, {:.1f} MB",
               st.passesDone, st.photonsShot, st.photonHits, st.cameraSeconds, st.photonSeconds, st.meanRadius,
               st.bytes / 1e6);
  return img;
}

}  // namespace

KernelSettings kernelSettings(const Scene& scene, const RenderOptions& opts) {
  const IntegratorSettings& is = scene.integrator;
  KernelSettings k;
  if (is.type == "path") k.type = SampleIntegratorType::Path;
  else if (is.type == "direct") k.type = SampleIntegratorType::Direct;
  else throw std::runtime_error("integrator '" + is.type + "' has no per-sample kernel (path and direct do)");
  k.spp = opts.spp > 0 ? opts.spp : scene.sampler.sampleCount;
  if (k.spp <= 0) throw std::runtime_error("samples per pixel must be positive");
  k.path.maxDepth = is.maxDepth;
  k.path.rrDepth = is.rrDepth;
  k.path.hideEmitters = is.hideEmitters;
  const StrategyName& sn = findStrategy(is.strategy);
  k.path.envStrategy = sn.env;
  k.direct.hideEmitters = is.hideEmitters;
  k.direct.envStrategy = sn.env;
  k.direct.emitterSamples = is.emitterSamples >= 0 ? is.emitterSamples : sn.emitterSamples;
  k.direct.bsdfSamples = is.bsdfSamples >= 0 ? is.bsdfSamples : sn.bsdfSamples;
  if (k.type == SampleIntegratorType::Direct && k.direct.emitterSamples + k.direct.bsdfSamples == 0)
    throw std::runtime_error("direct integrator: no samples");
  // A compensated map density is zero where L is below its mean: only with BSDF samples beside
  // it does every direction get covered (Karlik et al. 2019).
  bool compensated = scene.env && scene.env->options().misCompensation;
  bool mapDensity = k.direct.envStrategy == EnvStrategy::Alias || k.direct.envStrategy == EnvStrategy::Importance;
  if (k.type == SampleIntegratorType::Direct && compensated && mapDensity && k.direct.emitterSamples > 0 &&
      k.direct.bsdfSamples == 0)
    throw std::runtime_error("direct integrator: mis_compensation samples only the map's bright part; it needs "
                             "bsdf_samples > 0 (or the strategy 'mis') to cover the rest");
  k.sequence.type = scene.sampler.type;
  k.sequence.spp = uint32_t(k.spp);
  k.sequence.seed = scene.sampler.seed;
  return k;
}

Image renderPasses(PassExecutor& ex, int W, int H, int spp, const RenderOptions& opts, RenderStats* stats) {
  // Passes double in size (1, 1, 2, 4, ...) up to the executor's limit (64 samples on the CPU),
  // so a checkpoint comes early.
  std::vector<std::pair<int, int>> passes;
  const int maxPass = std::max(1, ex.maxPassSize());
  for (int s = 0, n = 1; s < spp; s += n, n = std::min(2 * n, maxPass)) passes.push_back({s, std::min(spp, s + n)});
  Progress progress(size_t(W) * H * spp, opts.progress);
  PassCounters counters;
  FilmSums film;
  auto t0 = Clock::now();
  auto lastCheckpoint = t0;
  int sppDone = 0;
  bool cancelled = false;
  auto meanImage = [&](int n) {
    ex.readFilm(&film);
    Image img(W, H);
    for (size_t i = 0; i < film.sum.size(); ++i) {
      Color c = film.sum[i] / float(n);
      img.rgb[3 * i] = c.x;
      img.rgb[3 * i + 1] = c.y;
      img.rgb[3 * i + 2] = c.z;
    }
    return img;
  };
  for (auto [s0, s1] : passes) {
    if (opts.cancel && opts.cancel->load()) {
      cancelled = true;
      break;
    }
    ex.runPass(s0, s1, progress, &counters);
    sppDone = s1;
    double sinceCheckpoint = std::chrono::duration<double>(Clock::now() - lastCheckpoint).count();
    if (opts.checkpoint && opts.checkpointSeconds > 0.0 && sinceCheckpoint >= opts.checkpointSeconds && sppDone < spp) {
      opts.checkpoint(meanImage(sppDone), sppDone);
      lastCheckpoint = Clock::now();
    }
  }
  Image img = meanImage(std::max(sppDone, 1));
  if (stats) {
    stats->seconds = std::chrono::duration<double>(Clock::now() - t0).count();
    stats->sppDone = sppDone;
    stats->rays = counters.rays;
    stats->nonFiniteSamples = counters.dropped;
    stats->cancelled = cancelled;
  }
  if (opts.varianceOut && sppDone > 0) {
    if (film.sumSqLum.empty()) throw std::runtime_error("this executor kept no per-pixel variance");
    opts.varianceOut->assign(size_t(W) * H, 0.f);
    for (size_t i = 0; i < film.sum.size(); ++i) {
      double mean = luminance(film.sum[i]) / sppDone;
      double var = std::max(0.0, film.sumSqLum[i] / sppDone - mean * mean);
      (*opts.varianceOut)[i] = float(var / std::max(1, sppDone - 1));
    }
  }
  if (counters.dropped > 0) spdlog::warn("{} samples were NaN, infinite or negative and were dropped", counters.dropped);
  return img;
}

Image render(const Scene& scene, const EmbreeAccel& accel, const RenderOptions& opts, RenderStats* stats) {
  const SceneView& sc = scene.view();
  const Camera& cam = sc.camera;
  const IntegratorSettings& is = scene.integrator;
  if (is.type == "sppm") return renderSppm(scene, accel, opts, stats);
  bool keepVar = opts.varianceOut != nullptr;
  EmbreeTracer embree{&accel};
  if (is.type == "photon") {
    int spp = opts.spp > 0 ? opts.spp : scene.sampler.sampleCount;
    if (spp <= 0) throw std::runtime_error("samples per pixel must be positive");
    PhotonMap globalMap, causticMap;
    PhotonRenderParams php;
    float radius = makePhotonEmitter(scene).radius;
    PhotonShootSettings ps;
    ps.irradianceRadius = is.maxRadius > 0.f ? is.maxRadius : 0.05f * radius;
    ps.irradianceStride = is.gatherSamples > 0 ? 4 : 0;
    ps.globalPhotons = is.globalPhotons;
    ps.causticPhotons = is.causticPhotons;
    ps.seed = scene.sampler.seed;
    ps.progress = opts.progress;
    PhotonShootStats pst;
    shootPhotons(scene, accel, ps, &globalMap, &causticMap, &pst);
    logPhotonStats(pst);
    php.global.k = php.caustic.k = is.lookupSize;
    php.global.maxRadius = is.maxRadius > 0.f ? is.maxRadius : 0.05f * radius;
    php.caustic.maxRadius = 0.25f * php.global.maxRadius;
    php.global.coneFilter = php.caustic.coneFilter = is.coneFilter;
    php.gatherSamples = is.gatherSamples;
    php.maxDepth = is.maxDepth > 0 ? is.maxDepth : 16;
    php.hideEmitters = is.hideEmitters;
    php.strategy = strategyOf(is.strategy);
    auto photon = [&](const Ray& ray, Sampler& smp, uint64_t* rays) {
      return photonTrace(sc, embree, ray, smp, globalMap, causticMap, php, rays);
    };
    SampleSequence seq{scene.sampler.type, uint32_t(spp), scene.sampler.seed};
    CpuExecutor<decltype(photon)> ex(cam, seq, photon, opts.threads, keepVar, "cpu", opts.tileSize);
    return renderPasses(ex, cam.width, cam.height, spp, opts, stats);
  }
  KernelSettings k = kernelSettings(scene, opts);
  if (opts.cpuTracer == CpuTracer::Bvh) {
    Bvh bvh(scene);
    SampleIntegrator<BvhTracer> integ{k.type, k.path, k.direct, &sc, BvhTracer{bvh.view()}};
    CpuExecutor<decltype(integ)> ex(cam, k.sequence, integ, opts.threads, keepVar, "cpu (envgi BVH)", opts.tileSize);
    return renderPasses(ex, cam.width, cam.height, k.spp, opts, stats);
  }
  SampleIntegrator<EmbreeTracer> integ{k.type, k.path, k.direct, &sc, embree};
  CpuExecutor<decltype(integ)> ex(cam, k.sequence, integ, opts.threads, keepVar, "cpu", opts.tileSize);
  return renderPasses(ex, cam.width, cam.height, k.spp, opts, stats);
}

}  // namespace envgi
