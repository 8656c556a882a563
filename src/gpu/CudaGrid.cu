// The grid integrator on a CUDA GPU: photon maps traced on the device (CudaPhotons) and built on
// the host, their precomputed irradiance uploaded as IrradianceCaches, then one thread a grid
// point runs gridPointGather (the CPU's body), the host averages the sums into the grid
// (finishGather, as the CPU), and the camera passes run GridSample, the CPU's per-sample body.
#include <spdlog/spdlog.h>

#include <chrono>

#include "gpu/CudaPassExecutor.cuh"
#include "render/IlluminationGridBuilder.h"

namespace envgi::gpu {

namespace {

constexpr int kThreads = 64;

__global__ void gridGatherKernel(const SceneView* sc, BvhTracer tracer, IlluminationGridView grid, ChainParams cp,
                                 IrradianceCacheView global, IrradianceCacheView caustic, uint32_t seed, int first,
                                 int rays, int n, ShL1* sums, int* backs, unsigned long long* rayCount) {
  int i = int(blockIdx.x * blockDim.x + threadIdx.x);
  if (i >= n) return;
  uint64_t r = 0;
  gridPointGather(*sc, tracer, grid.point(size_t(i)), uint64_t(i), cp, global, caustic, seed, first, rays, &sums[i],
                  &backs[i], &r);
  atomicAdd(rayCount, (unsigned long long)r);
}

IrradianceCacheView uploadCache(DeviceArena& a, const IrradianceCache& c) {
  IrradianceCacheView v = c.view();
  size_t n = c.points().size();
  v.points = a.upload(c.points().data(), n, "photon irradiance");
  v.grid.bucketStart = a.upload(v.grid.bucketStart, size_t(v.grid.tableSize) + 1, "photon irradiance");
  v.grid.items = a.upload(v.grid.items, n, "photon irradiance");
  if (n == 0) v.grid.tableSize = 0;
  return v;
}

}  // namespace

std::unique_ptr<PassExecutor> makeCudaGridExecutor(const Scene& scene, const Bvh& bvh, GridExecutorSettings s,
                                                   SampleSequence seq, int gpu, bool keepVariance,
                                                   size_t* deviceBytes) {
  selectDevice(gpu);
  if (!s.photons.tracer) s.photons.tracer = makeCudaPhotonTracer(scene, bvh, gpu, s.photons.maxDepth);
  GridBuild b;
  b.grid = makeIlluminationGrid(scene, s.resolution);
  shootPhotons(scene, s.photons, &b.global, &b.caustic, &b.photonStats);

  auto t0 = std::chrono::steady_clock::now();
  auto ds = std::make_unique<DeviceScene>(scene, bvh);
  DeviceArena& a = ds->arena;
  IrradianceCacheView global = uploadCache(a, b.global.irradianceCache());
  IrradianceCacheView caustic = uploadCache(a, b.caustic.irradianceCache());
  int n = int(b.grid.pointCount());
  ShL1* sums = a.allocate<ShL1>(size_t(n), "grid gather sums");
  int* backs = a.allocate<int>(size_t(n), "grid gather sums");
  unsigned long long* rays = a.allocate<unsigned long long>(1, "counters");
  check(cudaMemset(rays, 0, sizeof(unsigned long long)), "clearing counters");
  gridGatherKernel<<<(n + kThreads - 1) / kThreads, kThreads>>>(ds->deviceView, BvhTracer{ds->bvh}, b.grid.view(),
                                                                s.params.chain, global, caustic, s.seed, 0,
                                                                s.gatherRays, n, sums, backs, rays);
  check(cudaGetLastError(), "launching the grid gather kernel");
  std::vector<ShL1> hostSums(static_cast<size_t>(n));
  std::vector<int> hostBacks(static_cast<size_t>(n));
  unsigned long long rayCount = 0;
  check(cudaMemcpy(hostSums.data(), sums, size_t(n) * sizeof(ShL1), cudaMemcpyDeviceToHost), "filling the grid");
  check(cudaMemcpy(hostBacks.data(), backs, size_t(n) * sizeof(int), cudaMemcpyDeviceToHost), "filling the grid");
  check(cudaMemcpy(&rayCount, rays, sizeof(rayCount), cudaMemcpyDeviceToHost), "filling the grid");
  for (int i = 0; i < n; ++i) b.grid.accumulate(size_t(i), hostSums[size_t(i)], s.gatherRays, hostBacks[size_t(i)]);
  finishGather(b.grid, rayCount, std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count(),
               &b.gridStats);
  logGridBuild(b, s.gatherRays);

  IlluminationGridView gv = b.grid.view();
  gv.sh = a.upload(gv.sh, size_t(n), "illumination grid");
  gv.weight = a.upload(gv.weight, size_t(n), "illumination grid");
  GridSample<BvhTracer> sample{ds->deviceView, BvhTracer{ds->bvh}, gv, caustic, s.params};
  auto ex = std::make_unique<CudaPassExecutor<GridSample<BvhTracer>>>(std::move(ds), sample, scene.view().camera, seq,
                                                                      gpu, keepVariance);
  if (deviceBytes) *deviceBytes = ex->deviceBytes();
  return ex;
}

}  // namespace envgi::gpu
