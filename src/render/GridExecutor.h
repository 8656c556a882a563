// The grid integrator's CPU driver: photon maps, then the illumination grid filled from them,
// at construction; then camera passes (oneTBB over tiles) that read the grid, with refine_rays
// more gather rays a point before each pass after the first, up to max_gather_rays (the paper's
// grid "refined as the time budget allows"). The tracer is Embree, or the BVH the GPU
// traverses (to check the GPU's bodies on the CPU).
#pragma once

#include <memory>

#include "render/CpuExecutor.h"
#include "render/IlluminationGridBuilder.h"

namespace envgi {

template <class Tracer>
class GridExecutor final : public PassExecutor {
 public:
  GridExecutor(const Scene& scene, Tracer tracer, const GridExecutorSettings& s, SampleSequence seq, int threads,
               bool keepVariance, int tileSize)
      : scene_(scene), tracer_(tracer), settings_(s) {
    buildGridOnCpu(scene, tracer, s, &build_);
    GridSample<Tracer> sample{&scene.view(), tracer, build_.grid.view(), build_.caustic.irradianceCache().view(),
                              s.params};
    camera_ = std::make_unique<CpuExecutor<GridSample<Tracer>>>(scene.view().camera, seq, sample, threads,
                                                                keepVariance, "cpu", tileSize);
  }
  std::string deviceName() const override { return "cpu"; }
  void runPass(int s0, int s1, Progress& progress, PassCounters* counters) override {
    if (passes_++ > 0) refine();
    camera_->runPass(s0, s1, progress, counters);
  }
  void readFilm(FilmSums* out) override { camera_->readFilm(out); }
  bool restart(const Camera& cam) override { return camera_->restart(cam); }
  bool setActivePixels(const std::vector<unsigned char>& mask) override { return camera_->setActivePixels(mask); }
  bool keepsVariance() const override { return camera_->keepsVariance(); }
  const GridBuild& build() const { return build_; }
  int gatherRaysDone() const { return build_.grid.raysPerPoint(); }

 private:
  void refine() {
    int done = build_.grid.raysPerPoint(), add = settings_.raysToAdd(done);
    if (add > 0)
      gatherIntoGrid(build_.grid, scene_, tracer_, build_.global, build_.caustic, settings_, done, add,
                     &build_.gridStats);
  }

  const Scene& scene_;
  Tracer tracer_;
  GridExecutorSettings settings_;
  int passes_ = 0;
  GridBuild build_;
  std::unique_ptr<CpuExecutor<GridSample<Tracer>>> camera_;
};

}  // namespace envgi
