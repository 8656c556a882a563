// The grid integrator's CPU driver: photon maps, then the illumination grid filled from them,
// at construction; then camera passes (oneTBB over tiles) that read the grid. The tracer is
// Embree, or the BVH the GPU traverses (to check the GPU's bodies on the CPU). The grid is not
// refined while the passes run.
#pragma once

#include <memory>

#include "render/CpuExecutor.h"
#include "render/IlluminationGridBuilder.h"

namespace envgi {

template <class Tracer>
class GridExecutor final : public PassExecutor {
 public:
  GridExecutor(const Scene& scene, Tracer tracer, const GridExecutorSettings& s, SampleSequence seq, int threads,
               bool keepVariance, int tileSize) {
    buildGridOnCpu(scene, tracer, s, &build_);
    GridSample<Tracer> sample{&scene.view(), tracer, build_.grid.view(), build_.caustic.irradianceCache().view(),
                              s.params};
    camera_ = std::make_unique<CpuExecutor<GridSample<Tracer>>>(scene.view().camera, seq, sample, threads,
                                                                keepVariance, "cpu", tileSize);
  }
  std::string deviceName() const override { return "cpu"; }
  void runPass(int s0, int s1, Progress& progress, PassCounters* counters) override {
    camera_->runPass(s0, s1, progress, counters);
  }
  void readFilm(FilmSums* out) override { camera_->readFilm(out); }
  bool restart(const Camera& cam) override { return camera_->restart(cam); }
  const GridBuild& build() const { return build_; }

 private:
  GridBuild build_;
  std::unique_ptr<CpuExecutor<GridSample<Tracer>>> camera_;
};

}  // namespace envgi
