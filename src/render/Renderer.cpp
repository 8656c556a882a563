#include "render/Renderer.h"

#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <mutex>
#include <stdexcept>

#include "accel/Bvh.h"
#include "core/PhysicalMemory.h"
#include "render/ActivePixels.h"
#include "render/CpuExecutor.h"
#include "integrators/PhotonIntegrator.h"
#include "render/DirectionalGridExecutor.h"
#include "render/GridExecutor.h"
#include "render/SppmExecutor.h"
#include "scene/NameTables.h"
#include "render/PhotonShooter.h"

namespace envgi {

namespace {

using Clock = std::chrono::steady_clock;

// The first pass for the photon and grid integrators, with precomputed irradiance (stride 4)
// when final gathers will read it.
PhotonShootSettings photonShootSettings(const Scene& scene, const RenderOptions& opts, const PhotonSettings& ps,
                                        bool precompute) {
  float sceneRadius = makePhotonEmitter(scene).radius;
  PhotonShootSettings shoot;
  shoot.globalPhotons = ps.globalPhotons;
  shoot.causticPhotons = ps.causticPhotons;
  shoot.maxDepth = ps.maxDepth;
  shoot.irradianceRadius = ps.globalRadius(sceneRadius);
  shoot.causticIrradianceRadius = ps.causticRadius(sceneRadius);
  shoot.irradianceStride = precompute ? 4 : 0;
  shoot.seed = scene.sampler.seed;
  shoot.progress = opts.progress;
  shoot.tracer = opts.photonTracer;
  shoot.cancel = opts.cancel;
  return shoot;
}

ChainParams chainParams(const Scene& scene, int maxDepth, int rrDepth, bool hideEmitters) {
  ChainParams c;
  c.maxDepth = maxDepth;
  c.rrDepth = rrDepth;
  c.hideEmitters = hideEmitters;
  c.strategy = findStrategy(scene.integrator.env.strategy).env;
  return c;
}

// The photon integrator's second pass: camera samples that read the maps built beforehand.
struct PhotonSample {
  const SceneView* scene;
  EmbreeTracer tracer;
  std::shared_ptr<const PhotonMap> global, caustic;
  PhotonRenderParams params;
  Color operator()(const Ray& ray, Sampler& smp, uint64_t* rays) const {
    return photonTrace(*scene, tracer, ray, smp, *global, *caustic, params, rays);
  }
};

int samplesOf(const Scene& scene, const RenderOptions& opts) {
  int spp = opts.spp > 0 ? opts.spp : scene.sampler.sampleCount;
  if (spp <= 0) throw std::runtime_error("samples per pixel must be positive");
  return spp;
}

SampleSequence sequenceOf(const Scene& scene, int spp) {
  return SampleSequence{scene.sampler.type, uint32_t(spp), scene.sampler.seed};
}

}  // namespace

SppmParams sppmParams(const Scene& scene) {
  const SppmSettings& ss = scene.integrator.sppm;
  SppmParams sp;
  sp.photonsPerPass = ss.photonCount;
  sp.initialRadius = ss.initialRadius;
  sp.alpha = ss.alpha;
  sp.maxDepth = ss.maxDepth;
  sp.seed = scene.sampler.seed;
  sp.strategy = findStrategy(scene.integrator.env.strategy).env;
  return sp;
}

int sppmPasses(const Scene& scene, const RenderOptions& opts) {
  int passes = opts.spp > 0 ? opts.spp : scene.integrator.sppm.passes;
  if (passes <= 0) throw std::runtime_error("sppm: passes must be positive");
  return passes;
}

GridExecutorSettings gridExecutorSettings(const Scene& scene, const RenderOptions& opts) {
  const GridSettings& gs = scene.integrator.grid;
  PhotonSettings maps;  // the photon integrator's lookup radii, the grid's photon counts
  maps.globalPhotons = gs.globalPhotons;
  maps.causticPhotons = gs.causticPhotons;
  maps.maxDepth = gs.maxDepth;
  GridExecutorSettings ge;
  ge.photons = photonShootSettings(scene, opts, maps, true);
  ge.params.chain = chainParams(scene, gs.maxDepth, gs.rrDepth, gs.hideEmitters);
  ge.resolution = gs.resolution;
  ge.gatherRays = gs.gatherRays;
  ge.refineRays = gs.refineRays;
  ge.maxGatherRays = gs.maxGatherRays;
  ge.seed = scene.sampler.seed;
  ge.cancel = opts.cancel;
  return ge;
}

SequenceAndSpp gridSequence(const Scene& scene, const RenderOptions& opts) {
  int spp = samplesOf(scene, opts);
  return {sequenceOf(scene, spp), spp};
}

void logExecutorStats(const PassExecutor& ex) {
  if (auto* sppm = dynamic_cast<const SppmPassExecutor*>(&ex)) {
    SppmStats st = sppm->stats();
    spdlog::info("sppm: {} passes, {} photons ({} photon-visible-point hits), camera passes {:.2f} s, photon passes "
                 "{:.2f} s, mean final radius {:.4g}, {:.1f} MB",
                 st.passesDone, st.photonsShot, st.photonHits, st.cameraSeconds, st.photonSeconds, st.meanRadius,
                 st.bytes / 1e6);
  }
}

namespace {

// A CPU photon tracer over the same tracer as the camera passes.
std::shared_ptr<PhotonBatchTracer> cpuPhotonTracer(const Scene& scene, const EmbreeTracer& t) {
  return makeCpuPhotonTracer(scene, *t.accel);
}
std::shared_ptr<PhotonBatchTracer> cpuPhotonTracer(const Scene& scene, const BvhTracer& t) {
  return makeCpuPhotonTracer(scene, t.bvh);
}

// The integrators whose every step is a template over the tracer (path, direct, sppm, grid), on
// the CPU: with Embree, or with the GPU's BVH to check the GPU's bodies without a GPU.
template <class Tracer>
PreparedRender prepareOnTracer(const Scene& scene, const Tracer& tracer, const RenderOptions& opts, const char* name) {
  requireShareable(scene, opts);
  requireFilmFits(scene.view().camera, opts, physicalMemoryBytes());
  switch (scene.integrator.type) {
    case IntegratorType::Sppm:
      return {std::make_unique<SppmExecutor<Tracer>>(scene, tracer, sppmParams(scene), opts.threads),
              sppmPasses(scene, opts)};
    case IntegratorType::Grid: {
      GridExecutorSettings ge = gridExecutorSettings(scene, opts);
      if (!ge.photons.tracer) ge.photons.tracer = cpuPhotonTracer(scene, tracer);
      SequenceAndSpp q = gridSequence(scene, opts);
      if (scene.integrator.grid.basis == "directions") {
        auto ex = std::make_unique<DirectionalGridExecutor<Tracer>>(scene, tracer, ge, scene.integrator.grid.directions,
                                                                    q.sequence, opts.threads, opts.keepsVariance(),
                                                                    opts.tileSize);
        logPhotonStats(ex->photonStats());
        logDirectionalGrid(ex->grid(), ex->gridStats());
        return {std::move(ex), q.spp};
      }
      auto ex = std::make_unique<GridExecutor<Tracer>>(scene, tracer, ge, q.sequence, opts.threads,
                                                       opts.keepsVariance(), opts.tileSize);
      logGridBuild(ex->build(), ge.gatherRays);
      return {std::move(ex), q.spp};
    }
    case IntegratorType::Photon:
      throw std::logic_error("the photon integrator's kd-tree lookups run with Embree only");
    case IntegratorType::Path:
    case IntegratorType::Direct: break;
  }
  KernelSettings k = kernelSettings(scene, opts);
  const SceneView& sc = scene.view();
  SampleIntegrator<Tracer> integ{k.type, k.path, k.direct, &sc, tracer};
  return {std::make_unique<CpuExecutor<decltype(integ)>>(sc.camera, k.sequence, integ, opts.threads,
                                                         opts.keepsVariance(), name, opts.tileSize),
          k.spp};
}

PreparedRender preparePhoton(const Scene& scene, const EmbreeAccel& accel, const RenderOptions& opts) {
  requireShareable(scene, opts);
  requireFilmFits(scene.view().camera, opts, physicalMemoryBytes());  // before the photon pass
  const PhotonSettings& ps = scene.integrator.photon;
  int spp = samplesOf(scene, opts);
  auto globalMap = std::make_shared<PhotonMap>(), causticMap = std::make_shared<PhotonMap>();
  PhotonShootStats pst;
  shootPhotons(scene, accel, photonShootSettings(scene, opts, ps, ps.gatherSamples > 0), globalMap.get(),
               causticMap.get(), &pst);
  logPhotonStats(pst);
  float sceneRadius = makePhotonEmitter(scene).radius;
  PhotonRenderParams php;
  php.global.k = php.caustic.k = ps.lookupSize;
  php.global.maxRadius = ps.globalRadius(sceneRadius);
  php.caustic.maxRadius = ps.causticRadius(sceneRadius);
  php.global.coneFilter = php.caustic.coneFilter = ps.coneFilter;
  php.gatherSamples = ps.gatherSamples;
  php.chain = chainParams(scene, ps.maxDepth, ps.rrDepth, ps.hideEmitters);
  PhotonSample sample{&scene.view(), EmbreeTracer{&accel}, globalMap, causticMap, php};
  return {std::make_unique<CpuExecutor<PhotonSample>>(scene.view().camera, sequenceOf(scene, spp), sample,
                                                       opts.threads, opts.keepsVariance(), "cpu",
                                                       opts.tileSize),
          spp};
}

}  // namespace

KernelSettings kernelSettings(const Scene& scene, const RenderOptions& opts) {
  const IntegratorSettings& is = scene.integrator;
  KernelSettings k;
  switch (is.type) {
    case IntegratorType::Path: k.type = SampleIntegratorType::Path; break;
    case IntegratorType::Direct: k.type = SampleIntegratorType::Direct; break;
    case IntegratorType::Photon:
    case IntegratorType::Sppm:
    case IntegratorType::Grid:
      throw std::runtime_error(std::string("integrator '") + integratorName(is.type) +
                               "' has no per-sample kernel (path and direct do)");
  }
  k.spp = opts.spp > 0 ? opts.spp : scene.sampler.sampleCount;
  if (k.spp <= 0) throw std::runtime_error("samples per pixel must be positive");
  const StrategyName& sn = findStrategy(is.env.strategy);
  k.path.maxDepth = is.path.maxDepth;
  k.path.rrDepth = is.path.rrDepth;
  k.path.hideEmitters = is.path.hideEmitters;
  k.path.envStrategy = sn.env;
  k.direct.hideEmitters = is.direct.hideEmitters;
  k.direct.heuristic = is.direct.misHeuristic == "balance" ? MisHeuristic::Balance : MisHeuristic::Power;
  k.direct.envStrategy = sn.env;
  k.direct.emitterSamples = is.direct.emitterSamples >= 0 ? is.direct.emitterSamples : sn.emitterSamples;
  k.direct.bsdfSamples = is.direct.bsdfSamples >= 0 ? is.direct.bsdfSamples : sn.bsdfSamples;
  if (k.type == SampleIntegratorType::Direct && k.direct.emitterSamples + k.direct.bsdfSamples == 0)
    throw std::runtime_error("direct integrator: no samples");
  if (k.type == SampleIntegratorType::Direct && k.direct.emitterSamples == 0 && !scene.deltaLights.empty())
    spdlog::warn("direct integrator without emitter samples: the {} directional, point or spot light(s) add nothing "
                 "(only emitter samples reach them)",
                 scene.deltaLights.size());
  // Settings changed since finalize() (a caller's, the viewer's) are held to the same rule.
  scene.requireCompensationCovered();
  // A path's next-event estimation draws one light a bounce; the whole collapsed map at every
  // vertex is the paper's direct-light method, which direct, photon, sppm and grid take.
  if (k.type == SampleIntegratorType::Path && sn.env == EnvStrategy::PointsAll)
    throw std::runtime_error("strategy 'points' (every collapsed-map light at each point) is a direct-light method: "
                             "use it with direct, photon, sppm or grid, or 'points-draw' (one light a sample) with path");
  k.sequence.type = scene.sampler.type;
  k.sequence.spp = uint32_t(k.spp);
  k.sequence.seed = scene.sampler.seed;
  return k;
}

namespace {

// The film's first n pixels, each divided by its count samplesOf(i) (at least 1), or with a
// filter's weights, by their sum (a weighted mean, as pbrt-v4's and Mitsuba's films take): in a
// flat region the signed weights then cancel instead of adding noise. Where few samples leave
// the sum below a quarter of the count, the ratio would blow up: the plain mean, unbiased, is
// kept there.
template <class Samples>
Image meanOfFilm(const FilmSums& film, int width, int height, size_t n, Samples samplesOf) {
  Image img(width, height);
  const bool weighted = film.weightSum.size() >= n;
  for (size_t i = 0; i < n; ++i) {
    float count = float(std::max(samplesOf(i), 1));
    if (weighted && film.weightSum[i] > 0.25f * count) count = film.weightSum[i];
    Color c = film.sum[i] / count;
    img.rgb[3 * i] = c.x;
    img.rgb[3 * i + 1] = c.y;
    img.rgb[3 * i + 2] = c.z;
  }
  return img;
}

}  // namespace

Image filmMean(const FilmSums& film, int width, int height, int samples) {
  return meanOfFilm(film, width, height, std::min(film.sum.size(), size_t(width) * size_t(height)),
                    [samples](size_t) { return samples; });
}

Image filmMean(const FilmSums& film, int width, int height, const std::vector<int>& samples) {
  return meanOfFilm(film, width, height, std::min({film.sum.size(), samples.size(), size_t(width) * size_t(height)}),
                    [&samples](size_t i) { return samples[i]; });
}

size_t filmBytesPerPixel(const Camera& cam, const RenderOptions& opts) {
  const bool adaptive = opts.noiseThreshold > 0.f;
  size_t sums = sizeof(Color) + (opts.keepsVariance() ? sizeof(double) : 0) +
                (cam.filter.hasNegativeLobes() ? sizeof(float) : 0);
  // AOVs: each channel, and its copy in the image that is written; then that image's RGB copy.
  const size_t aovs = opts.aovChannels > 0 ? size_t(opts.aovChannels) * 2 * sizeof(float) + sizeof(Color) : 0;
  // The sums twice (renderPasses' FilmSums copies them, not the executor's mask).
  return 2 * sums + (adaptive ? 1 : 0) + sizeof(int) + 1 + sizeof(Color) + aovs;
}

void requireFilmFits(const Camera& cam, const RenderOptions& opts, double memoryBytes) {
  const double bytes = double(cam.width) * double(cam.height) * double(filmBytesPerPixel(cam, opts));
  const std::string aovs = opts.aovChannels > 0 ? fmt::format(" with {} AOV channels", opts.aovChannels) : "";
  requireFitsInHalfOfMemory(bytes, memoryBytes,
                            fmt::format("a {}x{} film{} would take about", cam.width, cam.height, aovs),
                            opts.aovChannels > 0 ? "render fewer pixels (the film's width and height) or fewer AOVs"
                                                 : "render fewer pixels (the film's width and height)");
}

namespace {

// The most of a render's time that checkpoints may take.
constexpr double kCheckpointShare = 0.1;

// A render's passes: samples [first, end), the pass that starts at s0 ending at passEnd(s0).
// Passes double the samples done (1, 1, 2, 4, ...) up to the executor's limit (64 samples on
// the CPU), so a checkpoint comes early, and each pass ends at a power of two or a multiple of
// the limit: there a pixel's Sobol samples so far are a net (Sampler::shuffledIndex), so a
// checkpoint or a time-limited render is as even as a render of that many samples.
// A pass also takes at most the executor's maxPassPixelSamples() (halving the limit, so it
// stays a power of two): on a large image a checkpoint, the time limit and Ctrl-C then come
// every few seconds, not after passes of 64 samples of every pixel (at 4096^2, minutes each).
// The passes depend on the image's size alone, so the same render sums the same film.
struct PassPlan {
  int first, end, maxPass;
  // One pass at a time: a list of them all (33 million for --spp 2147483647 and a time limit)
  // and s0 + n in int had overflowed into a hang.
  int passEnd(int s0) const { return int(std::min<int64_t>(end, int64_t(s0) + std::clamp(s0, 1, maxPass))); }
};

PassPlan planPasses(PassExecutor& ex, int W, int H, int spp, const RenderOptions& opts) {
  int maxPass = std::max(1, ex.maxPassSize());
  while (maxPass > 1 && double(maxPass) * double(W) * double(H) > double(ex.maxPassPixelSamples())) maxPass /= 2;
  const int first = opts.firstSample, end = opts.sampleEnd < 0 ? spp : opts.sampleEnd;
  if (first < 0 || first >= end || end > spp)
    throw std::runtime_error("the samples " + std::to_string(first) + ":" + std::to_string(end) +
                             " are not a range within the render's " + std::to_string(spp));
  if (first > 0 && opts.noiseThreshold > 0.f)
    throw std::runtime_error("adaptive sampling decides from each pixel's samples so far: it cannot render a range "
                             "that does not start at 0");
  return {first, end, maxPass};
}

// When checkpoints are written. A checkpoint stops the passes while it is written (an 8192²
// EXR: seconds), so the next waits at least ten times as long as this one took: they cost at
// most a tenth of the render.
class CheckpointClock {
 public:
  explicit CheckpointClock(double seconds) : seconds_(seconds), gap_(seconds), last_(Clock::now()) {}
  bool due() const { return seconds_ > 0.0 && std::chrono::duration<double>(Clock::now() - last_).count() >= gap_; }
  void written(Clock::time_point start) {
    last_ = Clock::now();
    const double took = std::chrono::duration<double>(last_ - start).count();
    gap_ = std::max(seconds_, took / kCheckpointShare);
    if (gap_ > seconds_ && !said_) {
      spdlog::info("checkpoints every {:.0f} s or more, not {:g}: writing one took {:.1f} s", gap_, seconds_, took);
      said_ = true;
    }
  }

 private:
  double seconds_, gap_;
  Clock::time_point last_;
  bool said_ = false;
};

// Each pixel's variance of the mean of its samples' luminance, from the film's sums.
void pixelVariances(const FilmSums& film, const std::vector<int>& samples, size_t pixels, std::vector<float>* out) {
  if (film.sumSqLum.empty()) throw std::runtime_error("this executor kept no per-pixel variance");
  out->assign(pixels, 0.f);
  for (size_t i = 0; i < film.sum.size(); ++i) {
    int n = std::max(samples[i], 1);
    double mean = luminance(film.sum[i]) / n;
    double var = std::max(0.0, film.sumSqLum[i] / n - mean * mean);
    (*out)[i] = float(var / std::max(1, n - 1));
  }
}

// Where a render's passes stopped, and why.
struct PassesDone {
  int sppDone = 0, sppAhead = 0;  // every pixel's samples; a cut pass's end, where Ctrl-C cut one
  size_t pixelsAhead = 0;         // the pixels that took the cut pass whole
  bool cancelled = false, timeLimited = false;
};

void recordStats(const PassesDone& done, const PassCounters& counters, const ActivePixels& pixels, size_t px,
                 double seconds, RenderStats* stats) {
  stats->seconds = seconds;
  stats->sppDone = done.sppDone;
  stats->rays = counters.rays;
  stats->nonFiniteSamples = counters.dropped;
  stats->cancelled = done.cancelled;
  stats->timeLimited = done.timeLimited;
  stats->pixelSamples = pixels.pixelSamples();
  stats->pixelsStopped = px - pixels.activeCount();  // 0 unless adaptive
  stats->converged = pixels.converged();
  stats->pixelsAhead = done.pixelsAhead;
  stats->sppAhead = done.sppAhead;
}

}  // namespace

Image renderPasses(PassExecutor& ex, int W, int H, int spp, const RenderOptions& opts, RenderStats* stats) {
  const PassPlan plan = planPasses(ex, W, H, spp, opts);
  const int first = plan.first, end = plan.end;
  Progress progress(size_t(W) * H * size_t(end - first), opts.progress, opts.timeLimitSeconds, opts.progressFraction);
  PassCounters counters;
  FilmSums film;
  auto t0 = Clock::now();
  CheckpointClock checkpoints(opts.checkpoint ? opts.checkpointSeconds : 0.0);
  PassesDone done;
  int& sppDone = done.sppDone;
  sppDone = first;
  const size_t px = size_t(W) * size_t(H);
  // Each pixel's samples so far, and adaptive sampling's mask: every pixel starts active.
  ActivePixels pixels(W, H, opts.noiseThreshold);
  const bool adaptive = pixels.attach(ex);
  if (opts.noiseThreshold > 0.f && !adaptive)
    throw std::runtime_error("adaptive sampling (a noise threshold) needs an integrator that samples pixels one by "
                             "one: path, direct, photon or grid, not sppm");
  auto meanImage = [&]() {
    ex.readFilm(&film);
    return filmMean(film, W, H, pixels.samples());
  };
  // Whether the pass that would start at s0 ends past the time limit, at the rate of the passes
  // so far, a pixel-sample at a time (adaptive passes shrink). Decided after each pass, before
  // its checkpoint, which is then left to the final write.
  auto pastTimeLimit = [&](int s0) {
    if (opts.timeLimitSeconds <= 0.0 || pixels.pixelSamples() == 0) return false;
    double spent = std::chrono::duration<double>(Clock::now() - t0).count();
    return spent + spent / double(pixels.pixelSamples()) * double(pixels.activeCount()) * (plan.passEnd(s0) - s0) >
           opts.timeLimitSeconds;
  };
  bool nextPastTimeLimit = false;
  for (int s0 = first, s1 = first; s0 < end; s0 = s1) {
    s1 = plan.passEnd(s0);
    done.cancelled = opts.cancel && opts.cancel->load();
    done.timeLimited = !done.cancelled && nextPastTimeLimit;
    if (done.cancelled || done.timeLimited) break;
    // Ctrl-C stops a pass at its next tile, but for the first, which every pixel takes whole
    // (an image with black tiles would not be finished work). The finished tiles' samples are
    // kept: each pixel's mean is over its own count.
    ex.watchCancel(s0 > first ? opts.cancel : nullptr);
    ex.runPass(s0, s1, progress, &counters);
    if (const std::vector<unsigned char>* took = ex.cutPass()) {
      done.pixelsAhead = pixels.passDone(s0, s1, *took);
      done.sppAhead = s1;
      done.cancelled = true;
      break;
    }
    pixels.passDone(s0, s1);
    sppDone = s1;
    if (adaptive && sppDone >= opts.adaptiveMinSpp && sppDone < end) {
      size_t before = pixels.activeCount();
      size_t left = pixels.update(ex, &film);
      progress.shrinkTotal((before - left) * size_t(end - sppDone));
      spdlog::debug("adaptive sampling: {} of {} pixels still sampling after {} spp", left, px, sppDone);
      if (left == 0) break;  // every pixel has converged: the render is done
    }
    nextPastTimeLimit = sppDone < end && pastTimeLimit(sppDone);
    if (checkpoints.due() && sppDone < end && !nextPastTimeLimit) {
      const auto start = Clock::now();
      opts.checkpoint(meanImage(), sppDone);
      checkpoints.written(start);
      nextPastTimeLimit = pastTimeLimit(sppDone);  // the write's time counts against the limit
    }
  }
  ex.watchCancel(nullptr);
  progress.finish();
  Image img = meanImage();
  if (opts.filmOut) *opts.filmOut = film;
  if (stats) recordStats(done, counters, pixels, px, std::chrono::duration<double>(Clock::now() - t0).count(), stats);
  if (opts.varianceOut && sppDone > 0) pixelVariances(film, pixels.samples(), px, opts.varianceOut);
  if (opts.samplesOut) *opts.samplesOut = pixels.samples();
  if (counters.dropped > 0) spdlog::warn("{} samples were NaN, infinite or negative and were dropped", counters.dropped);
  return img;
}

void requireLight(const Scene& scene) {
  if (!scene.env && scene.lightCount() == 0 && scene.deltaLights.empty() && scene.aovs.empty())
    throw std::runtime_error("the scene emits no light (no environment map, area light, or directional, point or spot "
                             "light envgi renders): its image would be black");
}

void requireShareable(const Scene& scene, const RenderOptions& opts) {
  if (opts.firstSample == 0 && opts.sampleEnd < 0) return;
  const std::string share = "samples " + std::to_string(opts.firstSample) + ":" + std::to_string(opts.sampleEnd);
  const IntegratorType t = scene.integrator.type;
  if (t != IntegratorType::Path && t != IntegratorType::Direct)
    throw std::runtime_error(share + ": only path's and direct's samples split into shares; " +
                             std::string(integratorName(t)) + " renders as a whole");
  if (opts.timeLimitSeconds > 0.0 || opts.noiseThreshold > 0.f)
    throw std::runtime_error(share + ": a share takes all of its samples (no time limit or noise threshold)");
}

PreparedRender prepareRender(const Scene& scene, const EmbreeAccel& accel, const RenderOptions& opts) {
  if (scene.integrator.type == IntegratorType::Photon) return preparePhoton(scene, accel, opts);
  return prepareOnTracer(scene, EmbreeTracer{&accel}, opts, "cpu");
}

Image render(const Scene& scene, const EmbreeAccel& accel, const RenderOptions& opts, RenderStats* stats) {
  const Camera& cam = scene.view().camera;
  std::unique_ptr<Bvh> bvh;  // outlives the executor that reads it
  PreparedRender pr;
  if (opts.cpuTracer == CpuTracer::Bvh && scene.integrator.type != IntegratorType::Photon) {
    bvh = std::make_unique<Bvh>(scene);
    pr = prepareOnTracer(scene, BvhTracer{bvh->view()}, opts, "cpu (envgi BVH)");
  } else {
    pr = prepareRender(scene, accel, opts);
  }
  Image img = renderPasses(*pr.executor, cam.width, cam.height, pr.spp, opts, stats);
  logExecutorStats(*pr.executor);
  return img;
}

}  // namespace envgi
