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
  std::unique_ptr<CpuExecutor<GridSample<EmbreeTracer>>> camera_;
};

}  // namespace envgi
