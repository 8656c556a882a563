#include "render/IlluminationGridBuilder.h"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <atomic>
#include <chrono>


namespace envgi {

IlluminationGrid makeIlluminationGrid(const Scene& scene, int resolution) {
  const SceneView& sc = scene.view();
  Vec3f ext = sc.boundsMax - sc.boundsMin;
  float longest = std::max({ext.x, ext.y, ext.z, 1e-6f});
  auto count = [&](float e) { return std::max(2, int(std::ceil(float(resolution - 1) * e / longest)) + 1); };
  // Half a cell of margin, so surfaces on the bounds still have points on both sides.
  Vec3f pad = Vec3f(0.5f * longest / float(resolution - 1));
  return IlluminationGrid(sc.boundsMin - pad, sc.boundsMax + pad, count(ext.x + 2 * pad.x), count(ext.y + 2 * pad.y),
                          count(ext.z + 2 * pad.z));
}

void gatherIntoGrid(IlluminationGrid& grid, const Scene& scene, const EmbreeAccel& accel, const PhotonMap& global,
                    const PhotonMap& caustic, const ChainParams& cp, uint32_t seed, int first, int rays,
                    GridBuildStats* stats) {
  auto t0 = std::chrono::steady_clock::now();
  const SceneView& sc = scene.view();
  EmbreeTracer tracer{&accel};
  std::atomic<uint64_t> rayCount{0};
  const IrradianceCacheView &g = global.irradianceCache().view(), &c = caustic.irradianceCache().view();
  tbb::parallel_for(size_t(0), grid.pointCount(), [&](size_t i) {
    ShL1 sum;
    int back = 0;
    uint64_t r = 0;
    gridPointGather(sc, tracer, grid.point(i), i, cp, g, c, seed, first, rays, &sum, &back, &r);
    grid.accumulate(i, sum, rays, back);
    rayCount += r;
  });
  grid.finish();
  if (stats) {
    stats->points = grid.pointCount();
    stats->insidePoints = 0;
    for (size_t i = 0; i < grid.pointCount(); ++i) stats->insidePoints += grid.view().weight[i] == 0.f;
    stats->rays += rayCount.load();
    stats->seconds += std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  }
}

}  // namespace envgi
