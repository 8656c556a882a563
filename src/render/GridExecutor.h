// The grid integrator's driver: photon maps, then the illumination grid filled from them, at
// construction; then camera passes (oneTBB over tiles) that read the grid. The grid is not
// refined while the passes run.
#pragma once

#include <memory>

#include "accel/EmbreeAccel.h"
#include "integrators/GridIntegrator.h"
#include "photon/PhotonMap.h"
#include "render/CpuExecutor.h"
#include "render/IlluminationGridBuilder.h"
#include "render/PhotonShooter.h"

namespace envgi {

// One camera sample of the grid integrator on the CPU (caustics from the caustic map).
struct GridSample {
  const SceneView* scene;
  EmbreeTracer tracer;
  IlluminationGridView grid;
  const PhotonMap* caustic;
  GridParams params;
  Color operator()(const Ray& ray, Sampler& smp, uint64_t* rays) const {
    auto caustics = [&](Vec3f p, Vec3f n) { return caustic->irradiance(p, n); };
    return gridTrace(*scene, tracer, ray, smp, grid, caustics, params, rays);
  }
};

struct GridExecutorSettings {
  PhotonShootSettings photons;
  GridParams params;
  int resolution = 32;
  int gatherRays = 128;
  uint32_t seed = 0;
};

class GridExecutor final : public PassExecutor {
 public:
  GridExecutor(const Scene& scene, const EmbreeAccel& accel, const GridExecutorSettings& s, SampleSequence seq,
               int threads, bool keepVariance, int tileSize);
  std::string deviceName() const override { return "cpu"; }
  void runPass(int s0, int s1, Progress& progress, PassCounters* counters) override {
    camera_->runPass(s0, s1, progress, counters);
  }
  void readFilm(FilmSums* out) override { camera_->readFilm(out); }
  bool restart(const Camera& cam) override { return camera_->restart(cam); }
  const PhotonShootStats& photonStats() const { return photonStats_; }
  const GridBuildStats& gridStats() const { return gridStats_; }
  const IlluminationGrid& grid() const { return grid_; }

 private:
  PhotonMap global_, caustic_;
  PhotonShootStats photonStats_;
  IlluminationGrid grid_;
  GridBuildStats gridStats_;
  std::unique_ptr<CpuExecutor<GridSample>> camera_;
};

}  // namespace envgi
