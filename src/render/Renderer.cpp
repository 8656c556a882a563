#include "render/Renderer.h"

#include <spdlog/spdlog.h>
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>
#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <mutex>
#include <stdexcept>

#include "integrators/DirectIntegrator.h"
#include "integrators/PathIntegrator.h"
#include "integrators/PhotonIntegrator.h"
#include "integrators/Sppm.h"
#include "photon/PhotonShooter.h"

namespace envgi {

namespace {

using Clock = std::chrono::steady_clock;

EnvStrategy strategyOf(const std::string& s) {
  if (s == "uniform") return EnvStrategy::Uniform;
  if (s == "cosine") return EnvStrategy::Cosine;
  if (s == "alias") return EnvStrategy::Alias;
  if (s == "adaptive") return EnvStrategy::Adaptive;
  if (s == "importance") return EnvStrategy::Importance;
  // mis (and path's default): Algorithm 1's density drawn through the alias table, which
  // bench_envmap measures 1.6x faster than the binary search.
  return EnvStrategy::Alias;
}

class Progress {
 public:
  Progress(size_t total, bool enabled) : total_(total), enabled_(enabled), tty_(::isatty(2)), start_(Clock::now()) {}
  void add(size_t n) {
    if (!enabled_) return;
    size_t done = done_.fetch_add(n) + n;
    std::lock_guard<std::mutex> lock(m_);
    double t = std::chrono::duration<double>(Clock::now() - start_).count();
    int pct = int(100.0 * double(done) / double(total_));
    if (tty_ ? (t - lastPrint_ < 0.2 && done < total_) : (pct < lastPct_ + 10 && done < total_)) return;
    lastPrint_ = t;
    lastPct_ = pct;
    double eta = done > 0 ? t * double(total_ - done) / double(done) : 0.0;
    int bar = pct / 4;
    std::fprintf(stderr, "%s[%.*s%*s] %3d%%  %.1fs elapsed, %.1fs left%s", tty_ ? "\r" : "", bar,
                 "=========================", 25 - bar, "", pct, t, eta, tty_ ? "" : "\n");
    if (tty_ && done >= total_) std::fprintf(stderr, "\n");
  }

 private:
  size_t total_;
  bool enabled_, tty_;
  Clock::time_point start_;
  std::atomic<size_t> done_{0};
  std::mutex m_;
  double lastPrint_ = -1.0;
  int lastPct_ = -100;
};

void logPhotonStats(const PhotonShootStats& st) {
  spdlog::info("photon pass: {} global photons stored ({} emitted), {} caustic ({} emitted), {:.2f} s tracing, "
               "{:.2f} s building kd-trees, {:.1f} MB ({} bytes a photon)",
               st.storedGlobal, st.emittedGlobal, st.storedCaustic, st.emittedCaustic, st.traceSeconds,
               st.buildSeconds, st.bytes / 1e6,
               st.storedGlobal + st.storedCaustic > 0 ? st.bytes / (st.storedGlobal + st.storedCaustic) : 0);
}

Image renderSppmFromSettings(const Scene& scene, const EmbreeAccel& accel, const RenderOptions& opts,
                             RenderStats* stats) {
  const IntegratorSettings& is = scene.integrator;
  SppmSettings ss;
  ss.passes = opts.spp > 0 ? opts.spp : is.passes;
  ss.photonsPerPass = is.photonCount;
  ss.initialRadius = is.initialRadius;
  ss.alpha = is.alpha;
  ss.maxDepth = is.maxDepth > 0 ? is.maxDepth : 16;
  ss.seed = scene.sampler.seed;
  ss.threads = opts.threads;
  ss.progress = opts.progress;
  ss.strategy = strategyOf(is.strategy);
  ss.checkpointSeconds = opts.checkpointSeconds;
  ss.checkpoint = opts.checkpoint;
  ss.cancel = opts.cancel;
  SppmStats st;
  Image img = renderSppm(scene, accel, ss, &st);
  spdlog::info("sppm: {} passes, {} photons ({} photon-visible-point hits), camera passes {:.2f} s, photon passes "
               "{:.2f} s, mean final radius {:.4g}, {:.1f} MB",
               st.passesDone, st.photonsShot, st.photonHits, st.cameraSeconds, st.photonSeconds,
               st.finalMeanRadius, st.bytes / 1e6);
  if (stats) {
    stats->seconds = st.seconds;
    stats->sppDone = st.passesDone;
    stats->rays = st.rays;
    stats->cancelled = st.cancelled;
  }
  return img;
}

}  // namespace

Image render(const Scene& scene, const EmbreeAccel& accel, const RenderOptions& opts, RenderStats* stats) {
  const SceneView& sc = scene.view();
  const Camera& cam = sc.camera;
  int W = cam.width, H = cam.height;
  const IntegratorSettings& is = scene.integrator;
  if (is.type == "sppm") return renderSppmFromSettings(scene, accel, opts, stats);
  int spp = opts.spp > 0 ? opts.spp : scene.sampler.sampleCount;
  if (spp <= 0) throw std::runtime_error("samples per pixel must be positive");
  bool direct = is.type == "direct";
  bool photon = is.type == "photon";
  if (!direct && !photon && is.type != "path") throw std::runtime_error("unknown integrator '" + is.type + "'");
  PhotonMap globalMap, causticMap;
  PhotonRenderParams php;
  if (photon) {
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
  }
  PathParams pp;
  pp.maxDepth = is.maxDepth;
  pp.rrDepth = is.rrDepth;
  pp.hideEmitters = is.hideEmitters;
  pp.envStrategy = strategyOf(is.strategy);
  DirectParams dp;
  dp.hideEmitters = is.hideEmitters;
  dp.envStrategy = strategyOf(is.strategy);
  dp.emitterSamples = is.emitterSamples >= 0 ? is.emitterSamples : (is.strategy == "bsdf" ? 0 : 1);
  dp.bsdfSamples = is.bsdfSamples >= 0 ? is.bsdfSamples : ((is.strategy == "mis" || is.strategy == "bsdf") ? 1 : 0);
  if (direct && dp.emitterSamples + dp.bsdfSamples == 0) throw std::runtime_error("direct integrator: no samples");

  EmbreeTracer tracer{&accel};
  int tilesX = (W + opts.tileSize - 1) / opts.tileSize, tilesY = (H + opts.tileSize - 1) / opts.tileSize;
  int tiles = tilesX * tilesY;
  std::vector<Color> sum(size_t(W) * H, Color(0.f));
  std::vector<double> sumSqLum(opts.varianceOut ? size_t(W) * H : 0, 0.0);
  std::atomic<uint64_t> rays{0}, nonFinite{0};

  // Passes double in size (1, 1, 2, 4, ...) up to 64 samples, so a checkpoint comes early.
  std::vector<std::pair<int, int>> passes;
  for (int s = 0, n = 1; s < spp; s += n, n = std::min(2 * n, 64)) passes.push_back({s, std::min(spp, s + n)});
  Progress progress(size_t(tiles) * spp, opts.progress);

  int threads = opts.threads > 0 ? opts.threads : tbb::this_task_arena::max_concurrency();
  tbb::task_arena arena(threads);
  auto t0 = Clock::now();
  auto lastCheckpoint = t0;
  int sppDone = 0;
  bool cancelled = false;
  auto meanImage = [&](int n) {
    Image img(W, H);
    for (size_t i = 0; i < sum.size(); ++i) {
      Color c = sum[i] / float(n);
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
    arena.execute([&] {
      tbb::parallel_for(tbb::blocked_range<int>(0, tiles, 1), [&](const tbb::blocked_range<int>& r) {
        uint64_t localRays = 0, localBad = 0;
        for (int t = r.begin(); t < r.end(); ++t) {
          int tx = t % tilesX, ty = t / tilesX;
          int x0 = tx * opts.tileSize, y0 = ty * opts.tileSize;
          int x1 = std::min(W, x0 + opts.tileSize), y1 = std::min(H, y0 + opts.tileSize);
          Sampler smp;
          smp.type = scene.sampler.type;
          smp.spp = uint32_t(spp);
          smp.seed = scene.sampler.seed;
          for (int y = y0; y < y1; ++y)
            for (int x = x0; x < x1; ++x) {
              Color acc(0.f);
              double accSq = 0.0;
              for (int s = s0; s < s1; ++s) {
                smp.start(uint64_t(y) * W + x, uint32_t(s));
                Vec2f off = sampleFilter(cam.filter, smp.get2D());
                Ray ray = cam.generateRay(x + 0.5f + off.x, y + 0.5f + off.y);
                Color L = direct   ? directTrace(sc, tracer, ray, smp, dp, &localRays)
                          : photon ? photonTrace(sc, tracer, ray, smp, globalMap, causticMap, php, &localRays)
                                   : pathTrace(sc, tracer, ray, smp, pp, &localRays);
                if (!isFiniteVec(L) || L.x < 0.f || L.y < 0.f || L.z < 0.f) {
                  ++localBad;
                  continue;
                }
                acc += L;
                accSq += double(luminance(L)) * luminance(L);
              }
              sum[size_t(y) * W + x] += acc;
              if (!sumSqLum.empty()) sumSqLum[size_t(y) * W + x] += accSq;
            }
          progress.add(size_t(s1 - s0));
        }
        rays += localRays;
        nonFinite += localBad;
      });
    });
    sppDone = s1;
    double sinceCheckpoint = std::chrono::duration<double>(Clock::now() - lastCheckpoint).count();
    if (opts.checkpoint && opts.checkpointSeconds > 0.0 && sinceCheckpoint >= opts.checkpointSeconds && sppDone < spp) {
      opts.checkpoint(meanImage(sppDone), sppDone);
      lastCheckpoint = Clock::now();
    }
  }
  if (stats) {
    stats->seconds = std::chrono::duration<double>(Clock::now() - t0).count();
    stats->sppDone = sppDone;
    stats->rays = rays.load();
    stats->nonFiniteSamples = nonFinite.load();
    stats->cancelled = cancelled;
  }
  if (opts.varianceOut && sppDone > 0) {
    opts.varianceOut->assign(size_t(W) * H, 0.f);
    for (size_t i = 0; i < sum.size(); ++i) {
      double mean = luminance(sum[i]) / sppDone;
      double var = std::max(0.0, sumSqLum[i] / sppDone - mean * mean);
      (*opts.varianceOut)[i] = float(var / std::max(1, sppDone - 1));
    }
  }
  if (nonFinite.load() > 0) spdlog::warn("{} samples were NaN, infinite or negative and were dropped", nonFinite.load());
  return meanImage(std::max(sppDone, 1));
}

}  // namespace envgi
