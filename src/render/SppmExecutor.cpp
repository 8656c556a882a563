#include "render/SppmExecutor.h"

#include <tbb/parallel_for.h>

#include <atomic>
#include <chrono>
#include <stdexcept>

namespace envgi {

namespace {
using Clock = std::chrono::steady_clock;
double since(Clock::time_point t) { return std::chrono::duration<double>(Clock::now() - t).count(); }
}  // namespace

SppmExecutor::SppmExecutor(const Scene& scene, const EmbreeAccel& accel, const SppmParams& params, int threads)
    : scene_(scene), tracer_{&accel}, p_(params),
      arena_(threads > 0 ? threads : tbb::this_task_arena::max_concurrency()), emitter_(makePhotonEmitter(scene)),
      anyLight_(emitter_.emitsLight(scene.view())), W_(scene.view().camera.width), H_(scene.view().camera.height) {
  if (p_.photonsPerPass == 0) throw std::runtime_error("sppm: photon_count must be positive");
  if (!(p_.alpha > 0.f && p_.alpha < 1.f)) throw std::runtime_error("sppm: alpha must be in (0, 1)");
  size_t np = size_t(W_) * H_;
  float r0 = p_.initialRadius > 0.f ? p_.initialRadius : 0.01f * emitter_.radius;
  r2_.assign(np, r0 * r0);
  n_.assign(np, 0.f);
  phi_.assign(np * 3, 0.f);
  tau_.assign(np, Color(0.f));
  ld_.assign(np, Color(0.f));
  m_.assign(np, 0);
  vps_.resize(np);
  vpPos_.resize(np);
  vpValid_.assign(np, 0);
}

void SppmExecutor::runPass(int s0, int s1, Progress& progress, PassCounters* counters) {
  for (int pass = s0; pass < s1; ++pass) {
    iteration(pass, counters);
    progress.add(size_t(W_) * H_);
  }
}

void SppmExecutor::iteration(int pass, PassCounters* counters) {
  const SceneView& sc = scene_.view();
  const Camera& cam = sc.camera;
  const int W = W_, N = W_ * H_;
  std::atomic<uint64_t> rays{0}, hits{0};
  auto tc = Clock::now();
  std::vector<Color>& ld = ld_;
  std::vector<VisiblePoint>& vps = vps_;
  std::vector<float>& r2 = r2_;
  std::vector<float>& phi = phi_;
  std::vector<uint32_t>& m = m_;
  const SppmParams& s = p_;
  const EmbreeTracer& tracer = tracer_;
  arena_.execute([&] {
    tbb::parallel_for(tbb::blocked_range<int>(0, N, 256), [&](const tbb::blocked_range<int>& r) {
      Sampler smp;
      smp.type = SamplerType::Independent;
      smp.seed = s.seed;
      uint64_t localRays = 0;
      for (int i = r.begin(); i < r.end(); ++i) {
        smp.start(uint64_t(i), uint32_t(pass));
        Vec2f off = sampleFilter(cam.filter, smp.get2D());
        Ray ray = cam.generateRay(float(i % W) + 0.5f + off.x, float(i / W) + 0.5f + off.y);
        Color L(0.f);
        vps[size_t(i)] = sppmCameraPath(sc, tracer, ray, smp, s.maxDepth, s.strategy, &L, &localRays);
        if (isFiniteVec(L)) ld[size_t(i)] += L;
        vpPos_[size_t(i)] = vps[size_t(i)].p;
        vpValid_[size_t(i)] = vps[size_t(i)].valid && isFiniteVec(vps[size_t(i)].beta) && !isBlack(vps[size_t(i)].beta);
      }
      rays += localRays;
    });
  });
  float maxR2 = 0.f;
  for (int i = 0; i < N; ++i)
    if (vpValid_[size_t(i)]) maxR2 = std::max(maxR2, r2[size_t(i)]);
  grid_.build(vpPos_, vpValid_, std::sqrt(std::max(maxR2, 1e-12f)));
  auto tp = Clock::now();
  st_.cameraSeconds += std::chrono::duration<double>(tp - tc).count();

  if (anyLight_) {
    HashGridView gv = grid_.view();
    const size_t chunk = 1024;
    size_t chunks = (s.photonsPerPass + chunk - 1) / chunk;
    const PhotonEmitter& emitter = emitter_;
    arena_.execute([&] {
      tbb::parallel_for(size_t(0), chunks, [&](size_t ci) {
        Sampler smp;
        smp.type = SamplerType::Independent;
        smp.seed = s.seed ^ kSppmPhotonStream;
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
  st_.photonsShot += s.photonsPerPass;
  // Progressive radius reduction: N' = N + alpha M, R'^2 = R^2 N'/(N + M).
  for (int i = 0; i < N; ++i) {
    uint32_t mi = m[size_t(i)];
    Color ph(phi[size_t(i) * 3], phi[size_t(i) * 3 + 1], phi[size_t(i) * 3 + 2]);
    if (mi > 0) {
      float nNew = n_[size_t(i)] + s.alpha * float(mi);
      float r2New = r2[size_t(i)] * nNew / (n_[size_t(i)] + float(mi));
      tau_[size_t(i)] = (tau_[size_t(i)] + ph) * (r2New / r2[size_t(i)]);
      n_[size_t(i)] = nNew;
      r2[size_t(i)] = r2New;
    }
    phi[size_t(i) * 3] = phi[size_t(i) * 3 + 1] = phi[size_t(i) * 3 + 2] = 0.f;
    m[size_t(i)] = 0;
  }
  st_.photonSeconds += since(tp);
  st_.passesDone = pass + 1;
  st_.photonHits += hits.load();
  st_.rays += rays.load();
  counters->rays += rays.load();
}

void SppmExecutor::readFilm(FilmSums* out) {
  size_t np = size_t(W_) * H_;
  int passes = std::max(st_.passesDone, 1);
  double photons = double(std::max<uint64_t>(st_.photonsShot, 1));
  out->sum.resize(np);
  out->sumSqLum.clear();
  for (size_t i = 0; i < np; ++i) {
    Color c = ld_[i] / float(passes) + tau_[i] / float(photons * kPi * r2_[i]);
    out->sum[i] = c * float(passes);
  }
}

SppmStats SppmExecutor::stats() const {
  SppmStats s = st_;
  size_t np = size_t(W_) * H_;
  s.bytes = grid_.bytes() + vps_.size() * sizeof(VisiblePoint) + np * (sizeof(float) * 5 + 2 * sizeof(Color) + 4);
  double rs = 0.0;
  for (float v : r2_) rs += std::sqrt(v);
  s.meanRadius = float(rs / double(np));
  return s;
}

}  // namespace envgi
