#include "render/IlluminationGridBuilder.h"

#include <spdlog/spdlog.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <atomic>
#include <chrono>

#include "accel/BvhView.h"
#include "core/PhysicalMemory.h"
#include "render/Cancellation.h"


namespace envgi {


GridBox gridBox(const Scene& scene, int resolution) {
  const SceneView& sc = scene.view();
  Vec3f ext = sc.boundsMax - sc.boundsMin;
  float longest = std::max({ext.x, ext.y, ext.z, 1e-6f});
  auto count = [&](float e) { return std::max(2, int(std::ceil(float(resolution - 1) * e / longest)) + 1); };
  Vec3f pad = Vec3f(0.5f * longest / float(resolution - 1));
  return {sc.boundsMin - pad, sc.boundsMax + pad, count(ext.x + 2 * pad.x), count(ext.y + 2 * pad.y),
          count(ext.z + 2 * pad.z)};
}

IlluminationGrid makeIlluminationGrid(const Scene& scene, int resolution) {
  const GridBox b = gridBox(scene, resolution);
  requireGridFits(b.nx, b.ny, b.nz, physicalMemoryBytes(), resolution);
  return IlluminationGrid(b.lo, b.hi, b.nx, b.ny, b.nz);
}

void requireGridFits(int nx, int ny, int nz, double memoryBytes, int resolution) {
  const double bytes = double(nx) * ny * nz * double(IlluminationGrid::kBytesPerPoint);
  requireFitsInHalfOfMemory(bytes, memoryBytes, fmt::format("grid: {}x{}x{} points would take", nx, ny, nz),
                            fmt::format("lower `resolution` ({})", resolution));
}

template <class Tracer>
void gatherIntoGrid(IlluminationGrid& grid, const Scene& scene, const Tracer& tracer, const PhotonMap& global,
                    const PhotonMap& caustic, const GridExecutorSettings& s, int first, int rays,
                    GridBuildStats* stats) {
  auto t0 = std::chrono::steady_clock::now();
  const SceneView& sc = scene.view();
  std::atomic<uint64_t> rayCount{0};
  const IrradianceCacheView &g = global.irradianceCache().view(), &c = caustic.irradianceCache().view();
  // Only the first fill stops early (then there is no pass to keep): a refinement runs to the
  // end, since every point must keep the same count of rays.
  const std::atomic<bool>* cancel = first == 0 ? s.cancel : nullptr;
  tbb::parallel_for(size_t(0), grid.pointCount(), [&](size_t i) {
    if (cancelRequested(cancel)) return;
    ShL1 sum;
    int back = 0;
    uint64_t r = 0;
    gridPointGather(sc, tracer, grid.point(i), i, s.params.chain, g, c, s.seed, first, rays, s.sequenceLength(), &sum,
                    &back, &r);
    grid.accumulate(i, sum, rays, back);
    rayCount += r;
  });
  throwIfCancelled(cancel);
  finishGather(grid, rayCount.load(), std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count(),
               stats);
}

void finishGather(IlluminationGrid& grid, uint64_t rays, double seconds, GridBuildStats* stats) {
  grid.finish();
  if (!stats) return;
  stats->points = grid.pointCount();
  stats->insidePoints = 0;
  for (size_t i = 0; i < grid.pointCount(); ++i) stats->insidePoints += grid.view().weight[i] == 0.f;
  stats->rays += rays;
  stats->seconds += seconds;
}

template <class Tracer>
void buildGridOnCpu(const Scene& scene, const Tracer& tracer, const GridExecutorSettings& s, GridBuild* out) {
  out->grid = makeIlluminationGrid(scene, s.resolution);
  shootPhotons(scene, s.photons, &out->global, &out->caustic, &out->photonStats);
  gatherIntoGrid(out->grid, scene, tracer, out->global, out->caustic, s, 0, s.gatherRays, &out->gridStats);
}

void logGridBuild(const GridBuild& b, int gatherRays) {
  logPhotonStats(b.photonStats);
  const GridBuildStats& gst = b.gridStats;
  const IlluminationGridView& gv = b.grid.view();
  spdlog::info("grid: {}x{}x{} points ({} inside geometry), {} gather rays each, {:.2f} M rays in {:.2f} s, {:.1f} MB",
               gv.nx, gv.ny, gv.nz, gst.insidePoints, gatherRays, gst.rays / 1e6, gst.seconds, b.grid.bytes() / 1e6);
}

template void gatherIntoGrid(IlluminationGrid&, const Scene&, const EmbreeTracer&, const PhotonMap&, const PhotonMap&,
                             const GridExecutorSettings&, int, int, GridBuildStats*);
template void gatherIntoGrid(IlluminationGrid&, const Scene&, const BvhTracer&, const PhotonMap&, const PhotonMap&,
                             const GridExecutorSettings&, int, int, GridBuildStats*);
template void buildGridOnCpu(const Scene&, const EmbreeTracer&, const GridExecutorSettings&, GridBuild*);
template void buildGridOnCpu(const Scene&, const BvhTracer&, const GridExecutorSettings&, GridBuild*);

}  // namespace envgi
