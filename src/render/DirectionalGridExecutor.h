// The grid integrator's CPU driver for the paper's own basis (`basis` = directions): photon
// maps, the M directions from the collapsed map, the grid filled by directionalPointGather;
// then camera passes that read it, with more samples of every direction before each pass after
// the first, up to the limit (the paper's step 4, "as the time budget allows").
#pragma once

#include <tbb/parallel_for.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <memory>

#include "integrators/DirectionalGridIntegrator.h"
#include "render/Cancellation.h"
#include "render/CpuExecutor.h"
#include "render/DirectionalGridBuilder.h"
#include "render/RefiningExecutor.h"

namespace envgi {

template <class Tracer>
class DirectionalGridExecutor final
    : public RefiningExecutor<CpuExecutor<GridSample<Tracer, DirectionalGridView>>> {
 public:
  DirectionalGridExecutor(const Scene& scene, Tracer tracer, const GridExecutorSettings& s, int directions,
                          SampleSequence seq, int threads, bool keepVariance, int tileSize)
      : scene_(scene), tracer_(tracer), settings_(s) {
    grid_ = makeDirectionalGrid(scene, s.resolution, directions, s.seed);
    shootPhotons(scene, s.photons, &global_, &caustic_, &photonStats_);
    gather(0, directionalSamples(s.gatherRays, grid_.directions()), s.cancel);
    GridSample<Tracer, DirectionalGridView> sample{&scene.view(), tracer, grid_.view(), caustic_.irradianceCache().view(),
                                         s.params};
    this->camera_ = std::make_unique<CpuExecutor<GridSample<Tracer, DirectionalGridView>>>(scene.view().camera, seq, sample, threads,
                                                                           keepVariance, "cpu", tileSize);
  }
  const DirectionalGrid& grid() const { return grid_; }
  const PhotonShootStats& photonStats() const { return photonStats_; }
  const GridBuildStats& gridStats() const { return stats_; }

 private:

  void refine() override {
    const int done = grid_.samplesPerDirection(), add = directionalSamplesToAdd(settings_, grid_.directions(), done);
    if (add > 0) gather(done, add, nullptr);
  }

  void gather(int first, int samples, const std::atomic<bool>* cancel) {
    auto t0 = std::chrono::steady_clock::now();
    const SceneView& sc = scene_.view();
    const IrradianceCacheView &g = global_.irradianceCache().view(), &c = caustic_.irradianceCache().view();
    const int length = directionalSequenceLength(settings_, grid_.directions());
    std::atomic<uint64_t> rays{0};
    tbb::parallel_for(size_t(0), grid_.pointCount(), [&](size_t i) {
      if (cancelRequested(cancel)) return;
      std::vector<Color> sums(size_t(grid_.directions()));
      int back = 0;
      uint64_t r = 0;
      directionalPointGather(sc, tracer_, grid_.view(), i, settings_.params.chain, g, c, settings_.seed, first, samples,
                             length, sums.data(), &back, &r);
      grid_.accumulate(i, sums.data(), samples, back);
      rays += r;
    });
    throwIfCancelled(cancel);
    grid_.finish();
    stats_.points = grid_.pointCount();
    stats_.rays += rays.load();
    stats_.seconds += std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  }

  const Scene& scene_;
  Tracer tracer_;
  GridExecutorSettings settings_;
  DirectionalGrid grid_;
  PhotonMap global_, caustic_;
  PhotonShootStats photonStats_;
  GridBuildStats stats_;
};

}  // namespace envgi
