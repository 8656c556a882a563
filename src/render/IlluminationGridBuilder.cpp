#include "render/IlluminationGridBuilder.h"

#include <spdlog/spdlog.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <atomic>
#include <chrono>

#include "accel/BvhView.h"
#include "core/PhysicalMemory.h"
#include "render/Cancellation.h"
#include "render/DirectionalGridExecutor.h"
#include "envmap/CollapsedMap.h"


namespace envgi {

namespace {
// The grid's box: the scene's bounds with half a cell of margin (so surfaces on the bounds still
// have points on both sides), `resolution` points along the longest side.
struct GridBox {
  Vec3f lo, hi;
  int nx, ny, nz;
};
GridBox gridBox(const Scene& scene, int resolution) {
  const SceneView& sc = scene.view();
  Vec3f ext = sc.boundsMax - sc.boundsMin;
  float longest = std::max({ext.x, ext.y, ext.z, 1e-6f});
  auto count = [&](float e) { return std::max(2, int(std::ceil(float(resolution - 1) * e / longest)) + 1); };
  Vec3f pad = Vec3f(0.5f * longest / float(resolution - 1));
  return {sc.boundsMin - pad, sc.boundsMax + pad, count(ext.x + 2 * pad.x), count(ext.y + 2 * pad.y),
          count(ext.z + 2 * pad.z)};
}
}  // namespace

IlluminationGrid makeIlluminationGrid(const Scene& scene, int resolution) {
  const GridBox b = gridBox(scene, resolution);
  requireGridFits(b.nx, b.ny, b.nz, physicalMemoryBytes(), resolution);
  return IlluminationGrid(b.lo, b.hi, b.nx, b.ny, b.nz);
}

void gridDirections(const Scene& scene, int m, uint32_t seed, std::vector<Vec3f>* dirs, std::vector<float>* share) {
  dirs->clear();
  share->clear();
  // Half the directions are the collapsed map's (Algorithm 1's draws), half a Fibonacci spiral
  // even over the sphere; each direction's share is 1 / (M p_mix), p_mix the two densities mixed
  // by their counts: the balance heuristic of Eq. 5-6 over the two sets. The map's draws alone
  // gave the map's dark half a few directions of huge share, and one of them, meeting a lit
  // surface, lit whole regions (the indirect light comes from surfaces, not from the map).
  const bool map = scene.env && scene.env->view().paperDist.integral() > 0.f;
  const int drawn = map ? m - m / 2 : 0, even = m - drawn;
  if (drawn > 0)
    for (const DirectionalLight& l : collapseByWeightedSampling(*scene.env, drawn, seed)) dirs->push_back(l.dir);
  for (int k = 0; k < even; ++k) {
    const float z = 1.f - 2.f * (float(k) + 0.5f) / float(even), r = std::sqrt(std::max(0.f, 1.f - z * z));
    const float phi = 2.39996323f * float(k);
    dirs->push_back(Vec3f(r * std::cos(phi), z, r * std::sin(phi)));
  }
  const EnvironmentMapView v = map ? scene.env->view() : EnvironmentMapView{};
  for (const Vec3f& d : *dirs) {
    const double pMix = (map ? double(drawn) * v.pdf(EnvStrategy::Algorithm1, d) : 0.0) + double(even) / (4.0 * M_PI);
    share->push_back(float(1.0 / pMix));  // 1 / (M p_mix), with M p_mix = sum of n_i p_i
  }
}

DirectionalGrid makeDirectionalGrid(const Scene& scene, int resolution, int m, uint32_t seed) {
  const GridBox b = gridBox(scene, resolution);
  const double bytes = double(b.nx) * b.ny * b.nz * double(DirectionalGrid::bytesPerPoint(m));
  requireFitsInHalfOfMemory(bytes, physicalMemoryBytes(), fmt::format("grid: {}x{}x{} points of {} directions would take", b.nx, b.ny, b.nz, m),
                            fmt::format("lower `resolution` ({}) or `directions` ({})", resolution, m));
  std::vector<Vec3f> dirs;
  std::vector<float> share;
  gridDirections(scene, m, seed, &dirs, &share);
  return DirectionalGrid(b.lo, b.hi, b.nx, b.ny, b.nz, std::move(dirs), std::move(share));
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
