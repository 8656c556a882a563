#include "integrators/Sppm.h"

#include <spdlog/spdlog.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include <chrono>

#include "photon/PhotonShooter.h"

namespace envgi {

Image renderSppm(const Scene& scene, const EmbreeAccel& accel, const SppmSettings& s, SppmStats* stats) {
  using Clock = std::chrono::steady_clock;
  const SceneView& sc = scene.view();
  const Camera& cam = sc.camera;
  const int W = cam.width, H = cam.height, N = W * H;
  const size_t np = size_t(N);
  if (s.passes <= 0 || s.photonsPerPass == 0) throw std::runtime_error("sppm: passes and photon_count must be positive");
  if (!(s.alpha > 0.f && s.alpha < 1.f)) throw std::runtime_error("sppm: alpha must be in (0, 1)");
  PhotonEmitter emitter = makePhotonEmitter(scene);
  float r0 = s.initialRadius > 0.f ? s.initialRadius : 0.01f * emitter.radius;
  bool anyLight = emitter.emitsLight(sc);

  std::vector<float> r2(np, r0 * r0), n(np, 0.f);
  std::vector<Color> tau(np, Color(0.f)), ld(np, Color(0.f));
  std::vector<float> phi(np * 3, 0.f);
  std::vector<uint32_t> m(np, 0);
  std::vector<VisiblePoint> vps(np);
  std::vector<Vec3f> vpPos(np);
  std::vector<char> vpValid(np, 0);
  HashGrid grid;
  EmbreeTracer tracer{&accel};
  int threads = s.threads > 0 ? s.threads : tbb::this_task_arena::max_concurrency();
  tbb::task_arena arena(threads);
  std::atomic<uint64_t> rays{0}, hits{0};
  auto t0 = Clock::now(), lastCheckpoint = t0;
  double camSec = 0.0, phSec = 0.0;
  int done = 0;
  bool cancelled = false;
  uint64_t totalPhotons = 0;

  auto image = [&](int passes) {
    Image img(W, H);
    double photons = double(std::max<uint64_t>(totalPhotons, 1));
    for (int i = 0; i < N; ++i) {
      Color c = ld[size_t(i)] / float(std::max(passes, 1)) + tau[size_t(i)] / float(photons * kPi * r2[size_t(i)]);
      img.set(i % W, i / W, c);
    }
    return img;
  };

  for (int pass = 0; pass < s.passes; ++pass) {
    if (s.cancel && s.cancel->load()) {
      cancelled = true;
      break;
    }
    auto tc = Clock::now();
    arena.execute([&] {
      tbb::parallel_for(tbb::blocked_range<int>(0, N, 256), [&](const tbb::blocked_range<int>& r) {
        Sampler smp;
        smp.type = SamplerType::Independent;
        smp.seed = scene.sampler.seed;
        uint64_t localRays = 0;
        for (int i = r.begin(); i < r.end(); ++i) {
          smp.start(uint64_t(i), uint32_t(pass));
          Vec2f off = sampleFilter(cam.filter, smp.get2D());
          Ray ray = cam.generateRay(float(i % W) + 0.5f + off.x, float(i / W) + 0.5f + off.y);
          Color L(0.f);
          vps[size_t(i)] = sppmCameraPath(sc, tracer, ray, smp, s.maxDepth, s.strategy, &L, &localRays);
          if (isFiniteVec(L)) ld[size_t(i)] += L;
          vpPos[size_t(i)] = vps[size_t(i)].p;
          vpValid[size_t(i)] = vps[size_t(i)].valid && isFiniteVec(vps[size_t(i)].beta) && !isBlack(vps[size_t(i)].beta);
        }
        rays += localRays;
      });
    });
    float maxR2 = 0.f;
    for (int i = 0; i < N; ++i)
      if (vpValid[size_t(i)]) maxR2 = std::max(maxR2, r2[size_t(i)]);
    grid.build(vpPos, vpValid, std::sqrt(std::max(maxR2, 1e-12f)));
    auto tp = Clock::now();
    camSec += std::chrono::duration<double>(tp - tc).count();

    if (anyLight) {
      HashGridView gv = grid.view();
      const size_t chunk = 1024;
      size_t chunks = (s.photonsPerPass + chunk - 1) / chunk;
      arena.execute([&] {
        tbb::parallel_for(size_t(0), chunks, [&](size_t ci) {
          Sampler smp;
          smp.type = SamplerType::Independent;
          smp.seed = scene.sampler.seed ^ 0x85ebca6bu;
          uint64_t localHits = 0;
          for (size_t j = ci * chunk; j < std::min(s.photonsPerPass, (ci + 1) * chunk); ++j) {
            smp.start(uint64_t(pass) * s.photonsPerPass + j, 1);
            Ray ray;
            Color power;
            if (!emitter.emit(sc, smp, &ray, &power)) continue;
            tracePhoton(sc, tracer, ray, power, smp, s.maxDepth,
                        [&](const SurfaceInteraction& si, Vec3f wi, Color pw, bool, int) {
                          gv.forNeighbours(si.p, [&](int idx) {
                            const VisiblePoint& vp = vps[size_t(idx)];
                            if (lengthSq(vp.p - si.p) > r2[size_t(idx)]) return;
                            Color c = sppmContribution(sc, vp, wi, pw);
                            if (!isFiniteVec(c)) return;
                            std::atomic_ref<float>(phi[size_t(idx) * 3]).fetch_add(c.x, std::memory_order_relaxed);
                            std::atomic_ref<float>(phi[size_t(idx) * 3 + 1]).fetch_add(c.y, std::memory_order_relaxed);
                            std::atomic_ref<float>(phi[size_t(idx) * 3 + 2]).fetch_add(c.z, std::memory_order_relaxed);
                            std::atomic_ref<uint32_t>(m[size_t(idx)]).fetch_add(1u, std::memory_order_relaxed);
                            ++localHits;
                          });
                        });
          }
          hits += localHits;
        });
      });
    }
    totalPhotons += s.photonsPerPass;
    // Progressive radius reduction: N' = N + alpha M, R'^2 = R^2 N'/(N + M).
    for (int i = 0; i < N; ++i) {
      uint32_t mi = m[size_t(i)];
      Color ph(phi[size_t(i) * 3], phi[size_t(i) * 3 + 1], phi[size_t(i) * 3 + 2]);
      if (mi > 0) {
        float nNew = n[size_t(i)] + s.alpha * float(mi);
        float r2New = r2[size_t(i)] * nNew / (n[size_t(i)] + float(mi));
        tau[size_t(i)] = (tau[size_t(i)] + ph) * (r2New / r2[size_t(i)]);
        n[size_t(i)] = nNew;
        r2[size_t(i)] = r2New;
      }
      phi[size_t(i) * 3] = phi[size_t(i) * 3 + 1] = phi[size_t(i) * 3 + 2] = 0.f;
      m[size_t(i)] = 0;
    }
    phSec += std::chrono::duration<double>(Clock::now() - tp).count();
    done = pass + 1;
    if (s.progress && (done == s.passes || done % std::max(1, s.passes / 10) == 0))
      spdlog::info("sppm: pass {}/{}, {} photons, {:.1f} s", done, s.passes, totalPhotons,
                   std::chrono::duration<double>(Clock::now() - t0).count());
    if (s.checkpoint && s.checkpointSeconds > 0.0 && done < s.passes &&
        std::chrono::duration<double>(Clock::now() - lastCheckpoint).count() >= s.checkpointSeconds) {
      s.checkpoint(image(done), done);
      lastCheckpoint = Clock::now();
    }
  }
  if (stats) {
    stats->passesDone = done;
    stats->photonsShot = totalPhotons;
    stats->photonHits = hits.load();
    stats->rays = rays.load();
    stats->cameraSeconds = camSec;
    stats->photonSeconds = phSec;
    stats->seconds = std::chrono::duration<double>(Clock::now() - t0).count();
    stats->bytes = grid.bytes() + vps.size() * sizeof(VisiblePoint) + size_t(N) * (sizeof(float) * 5 + 2 * sizeof(Color) + 4);
    double rs = 0.0;
    for (float v : r2) rs += std::sqrt(v);
    stats->finalMeanRadius = float(rs / N);
    stats->cancelled = cancelled;
  }
  return image(done);
}

}  // namespace envgi
