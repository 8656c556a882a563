// The grid integrator's CPU driver: photon maps, then the illumination grid filled from them,
// at construction; then camera passes (oneTBB over tiles) that read the grid, with refine_rays
// more gather rays a point before each pass after the first, up to max_gather_rays (the paper's
// grid "refined as the time budget allows"). The tracer is Embree, or the BVH the GPU
// traverses (to check the GPU's bodies on the CPU).
#pragma once

#include <memory>

#include "render/CpuExecutor.h"
#include "render/IlluminationGridBuilder.h"
#include "render/RefiningExecutor.h"

namespace envgi {

template <class Tracer>
class GridExecutor final : public RefiningExecutor<CpuExecutor<GridSample<Tracer>>> {
 public:
  GridExecutor(const Scene& scene, Tracer tracer, const GridExecutorSettings& s, SampleSequence seq, int threads,
               bool keepVariance, int tileSize)
      : scene_(scene), tracer_(tracer), settings_(s) {
    buildGridOnCpu(scene, tracer, s, &build_);
    GridSample<Tracer> sample{&scene.view(), tracer, build_.grid.view(), build_.caustic.irradianceCache().view(),
                              s.params};
    this->camera_ = std::make_unique<CpuExecutor<GridSample<Tracer>>>(scene.view().camera, seq, sample, threads,
                                                                keepVariance, "cpu", tileSize);
  }
  const GridBuild& build() const { return build_; }
  int gatherRaysDone() const { return build_.grid.raysPerPoint(); }

 private:
  void refine() override {
    int done = build_.grid.raysPerPoint(), add = settings_.raysToAdd(done);
    if (add > 0)
      gatherIntoGrid(build_.grid, scene_, tracer_, build_.global, build_.caustic, settings_, done, add,
                     &build_.gridStats);
  }

  const Scene& scene_;
  Tracer tracer_;
  GridExecutorSettings settings_;
  GridBuild build_;
};

}  // namespace envgi
