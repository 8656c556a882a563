#include "render/SppmExecutor.h"

#include <tbb/parallel_for.h>

#include <atomic>
#include <chrono>
#include <stdexcept>

#include "accel/BvhView.h"
#include "render/WorkerThreads.h"

namespace envgi {

namespace {
using Clock = std::chrono::steady_clock;
double since(Clock::time_point t) { return std::chrono::duration<double>(Clock::now() - t).count(); }
}  // namespace

void checkSppmParams(const SppmParams& p) {
  if (p.photonsPerPass == 0) throw std::runtime_error("sppm: photon_count must be positive");
  if (!(p.alpha > 0.f && p.alpha < 1.f)) throw std::runtime_error("sppm: alpha must be in (0, 1)");
}

template <class Tracer>
SppmExecutor<Tracer>::SppmExecutor(const Scene& scene, Tracer tracer, const SppmParams& params, int threads)
    : scene_(scene), tracer_(tracer), p_(params),
      arena_(arenaConcurrency(threads)), emitter_(makePhotonEmitter(scene)),
      anyLight_(emitter_.emitsLight(scene.view())), W_(scene.view().camera.width), H_(scene.view().camera.height) {
  checkSppmParams(p_);
  size_t np = size_t(W_) * H_;
  float r0 = sppmInitialRadius(p_, emitter_);
  r2_.assign(np, r0 * r0);
  n_.assign(np, 0.f);
  phi_.assign(np * 3, 0.f);
  tau_.assign(np, Color(0.f));
  ld_.assign(np, Color(0.f));
  m_.assign(np, 0);
  vps_.resize(np);
  vpPos_.resize(np);
  vpValid_.assign(np, 0);
  if (scene.view().camera.filter.hasNegativeLobes()) weightSum_.assign(np, 0.f);
}

template <class Tracer>
void SppmExecutor<Tracer>::runPass(int s0, int s1, Progress& progress, PassCounters* counters) {
  for (int pass = s0; pass < s1; ++pass) {
    iteration(pass, counters);
    progress.add(size_t(W_) * H_);
  }
}

template <class Tracer>
void SppmExecutor<Tracer>::iteration(int pass, PassCounters* counters) {
  const SceneView& sc = scene_.view();
  const int N = W_ * H_;
  SppmPixels px{vps_.data(), vpPos_.data(), vpValid_.data(), r2_.data(), n_.data(),
                phi_.data(),  m_.data(),     tau_.data(),     ld_.data(),
                weightSum_.empty() ? nullptr : weightSum_.data()};
  std::atomic<uint64_t> rays{0}, hits{0};
  auto tc = Clock::now();
  arena_.execute([&] {
    tbb::parallel_for(tbb::blocked_range<int>(0, N, 256), [&](const tbb::blocked_range<int>& r) {
      uint64_t local = 0;
      for (int i = r.begin(); i < r.end(); ++i) local += sppmCameraStep(sc, tracer_, p_, px, i, pass);
      rays += local;
    });
  });
  float maxR2 = 0.f;
  for (int i = 0; i < N; ++i)
    if (vpValid_[size_t(i)]) maxR2 = std::max(maxR2, r2_[size_t(i)]);
  grid_.build(vpPos_, vpValid_, std::sqrt(std::max(maxR2, 1e-12f)));
  auto tp = Clock::now();
  st_.cameraSeconds += std::chrono::duration<double>(tp - tc).count();

  if (anyLight_) {
    const HashGridView& gv = grid_.view();
    const size_t chunk = 1024;
    size_t chunks = (p_.photonsPerPass + chunk - 1) / chunk;
    arena_.execute([&] {
      tbb::parallel_for(size_t(0), chunks, [&](size_t ci) {
        uint64_t local = 0;
        size_t end = std::min(p_.photonsPerPass, (ci + 1) * chunk);
        shootInPrefetchedBlocks(
            ci * chunk, end,
            [&](uint64_t j) {
              Sampler smp = sppmPhotonSampler(p_, j, pass);
              emitter_.prefetch(sc, smp);
            },
            [&](uint64_t j) { local += sppmPhotonStep(sc, tracer_, emitter_, p_, px, gv, j, pass); });
        hits += local;
      });
    });
  }
  st_.photonsShot += p_.photonsPerPass;
  for (int i = 0; i < N; ++i) sppmUpdateStep(p_, px, i);
  st_.photonSeconds += since(tp);
  st_.passesDone = pass + 1;
  st_.photonHits += hits.load();
  st_.rays += rays.load();
  counters->rays += rays.load();
}

template <class Tracer>
void SppmExecutor<Tracer>::readFilm(FilmSums* out) {
  size_t np = size_t(W_) * H_;
  int passes = std::max(st_.passesDone, 1);
  double photons = double(std::max<uint64_t>(st_.photonsShot, 1));
  out->sum.resize(np);
  out->sumSqLum.clear();
  for (size_t i = 0; i < np; ++i) out->sum[i] = sppmRadiance(ld_[i], tau_[i], r2_[i], passes, photons) * float(passes);
  out->weightSum = weightSum_;
}

template <class Tracer>
SppmStats SppmExecutor<Tracer>::stats() const {
  SppmStats s = st_;
  size_t np = size_t(W_) * H_;
  s.bytes = grid_.bytes() + vps_.size() * sizeof(VisiblePoint) + np * (sizeof(float) * 5 + 2 * sizeof(Color) + 4);
  double rs = 0.0;
  for (float v : r2_) rs += std::sqrt(v);
  s.meanRadius = float(rs / double(np));
  return s;
}

template class SppmExecutor<EmbreeTracer>;
template class SppmExecutor<BvhTracer>;

}  // namespace envgi
