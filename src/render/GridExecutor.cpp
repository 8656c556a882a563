#include "render/GridExecutor.h"

namespace envgi {

GridExecutor::GridExecutor(const Scene& scene, const EmbreeAccel& accel, const GridExecutorSettings& s,
                           SampleSequence seq, int threads, bool keepVariance, int tileSize)
    : grid_(makeIlluminationGrid(scene, s.resolution)) {
  shootPhotons(scene, accel, s.photons, &global_, &caustic_, &photonStats_);
  gatherIntoGrid(grid_, scene, accel, global_, caustic_, s.params.chain, s.seed, 0, s.gatherRays, &gridStats_);
  GridSample<EmbreeTracer> sample{&scene.view(), EmbreeTracer{&accel}, grid_.view(), caustic_.irradianceCache().view(),
                                  s.params};
  camera_ = std::make_unique<CpuExecutor<GridSample<EmbreeTracer>>>(scene.view().camera, seq, sample, threads, keepVariance, "cpu",
                                                      tileSize);
}

}  // namespace envgi
