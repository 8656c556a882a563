// The grid integrator on a CUDA GPU, in both bases: photon maps traced on the device
// (CudaPhotons) and built on the host, their precomputed irradiance uploaded as
// IrradianceCaches, then one thread a grid point runs the CPU's gather body (gridPointGather for
// the SH basis, directionalPointGather for the paper's M directions), the host adds the sums
// into the grid as the CPU does and uploads it, and the camera passes run GridSample, the CPU's
// per-sample body. Before each pass after the first, more rays a point refine the grid, as on
// the CPU.
#include <algorithm>
#include <chrono>

#include "gpu/CudaPassExecutor.cuh"
#include "render/Cancellation.h"
#include "integrators/DirectionalGridIntegrator.h"
#include "render/DirectionalGridBuilder.h"
#include "render/IlluminationGridBuilder.h"
#include "render/RefiningExecutor.h"

namespace envgi::gpu {

namespace {

constexpr int kThreads = 64;

// Points a launch of the gather covers: between launches the host looks at Ctrl-C (the CPU's
// gather looks at it every point), so a 256^3 grid stops within a launch of milliseconds.
constexpr int kPointsPerLaunch = 1 << 16;

__global__ void gridGatherKernel(const SceneView* sc, BvhTracer tracer, IlluminationGridView grid, ChainParams cp,
                                 IrradianceCacheView global, IrradianceCacheView caustic, uint32_t seed, int first,
                                 int rays, int length, int begin, int end, ShL1* sums, int* backs,
                                 unsigned long long* rayCount) {
  int i = begin + int(blockIdx.x * blockDim.x + threadIdx.x);
  if (i >= end) return;
  uint64_t r = 0;
  gridPointGather(*sc, tracer, grid.point(size_t(i)), uint64_t(i), cp, global, caustic, seed, first, rays, length,
                  &sums[i], &backs[i], &r);
  atomicAdd(rayCount, (unsigned long long)r);
}

IrradianceCacheView uploadCache(DeviceArena& a, const IrradianceCache& c) {
  IrradianceCacheView v = c.view();
  size_t n = c.points().size();
  v.points = a.upload(c.points().data(), n, "photon irradiance");
  v.id = a.upload(c.ids().data(), n, "photon irradiance");
  for (int l = 0; l < v.levelCount; ++l) {
    // The lookup reads its points in bucket order from v.points, not through items.
    HashGridView& g = v.levels[l];
    g.bucketStart = a.upload(g.bucketStart, size_t(g.tableSize) + 1, "photon irradiance");
    g.items = nullptr;
  }
  return v;
}

class CudaGridExecutor final
    : public RefiningExecutor<CudaPassExecutor<GridSample<BvhTracer, IlluminationGridView>>> {
 public:
  CudaGridExecutor(const Scene& scene, const Bvh& bvh, const GridExecutorSettings& s, SampleSequence seq, int gpu,
                   bool keepVariance)
      : s_(s) {
    build_.grid = makeIlluminationGrid(scene, s.resolution);
    shootPhotons(scene, s.photons, &build_.global, &build_.caustic, &build_.photonStats);
    auto ds = std::make_unique<DeviceScene>(scene, bvh);
    DeviceArena& a = ds->arena;
    sceneView_ = ds->deviceView;
    tracer_ = BvhTracer{ds->bvh};
    global_ = uploadCache(a, build_.global.irradianceCache());
    caustic_ = uploadCache(a, build_.caustic.irradianceCache());
    n_ = int(build_.grid.pointCount());
    sums_ = a.allocate<ShL1>(size_t(n_), "grid gather sums");
    backs_ = a.allocate<int>(size_t(n_), "grid gather sums");
    rays_ = a.allocate<unsigned long long>(1, "counters");
    gridView_ = build_.grid.view();
    gridView_.sh = a.allocate<ShL1>(size_t(n_), "illumination grid");
    gridView_.weight = a.allocate<float>(size_t(n_), "illumination grid");
    gather(0, s.gatherRays);
    logGridBuild(build_, s.gatherRays);
    GridSample<BvhTracer, IlluminationGridView> sample{sceneView_, tracer_, gridView_, caustic_, s.params};
    camera_ = std::make_unique<CudaPassExecutor<GridSample<BvhTracer, IlluminationGridView>>>(
        std::move(ds), sample, scene.view().camera, seq, gpu, keepVariance);
  }

  size_t deviceBytes() const { return camera_->deviceBytes(); }

 private:
  void refine() override {
    int done = build_.grid.raysPerPoint(), add = s_.raysToAdd(done);
    if (add > 0) gather(done, add);
  }

  // Rays [first, first + rays) of every point on the device; the host adds them to the grid and
  // uploads the averaged coefficients.
  void gather(int first, int rays) {
    auto t0 = std::chrono::steady_clock::now();
    check(cudaMemset(rays_, 0, sizeof(unsigned long long)), "clearing counters");
    // As on the CPU, only the first fill stops early: a refinement runs to the end, since every
    // point must keep the same count of rays.
    const std::atomic<bool>* cancel = first == 0 ? s_.cancel : nullptr;
    for (int begin = 0; begin < n_; begin += kPointsPerLaunch) {
      throwIfCancelled(cancel);
      const int end = std::min(n_, begin + kPointsPerLaunch);
      gridGatherKernel<<<(end - begin + kThreads - 1) / kThreads, kThreads>>>(
          sceneView_, tracer_, gridView_, s_.params.chain, global_, caustic_, s_.seed, first, rays,
          s_.sequenceLength(), begin, end, sums_, backs_, rays_);
      check(cudaGetLastError(), "launching the grid gather kernel");
      if (cancel) check(cudaDeviceSynchronize(), "gathering into the grid");
    }
    throwIfCancelled(cancel);
    std::vector<ShL1> sums(static_cast<size_t>(n_));
    std::vector<int> backs(static_cast<size_t>(n_));
    unsigned long long rayCount = 0;
    check(cudaMemcpy(sums.data(), sums_, size_t(n_) * sizeof(ShL1), cudaMemcpyDeviceToHost), "filling the grid");
    check(cudaMemcpy(backs.data(), backs_, size_t(n_) * sizeof(int), cudaMemcpyDeviceToHost), "filling the grid");
    check(cudaMemcpy(&rayCount, rays_, sizeof(rayCount), cudaMemcpyDeviceToHost), "filling the grid");
    for (int i = 0; i < n_; ++i) build_.grid.accumulate(size_t(i), sums[size_t(i)], rays, backs[size_t(i)]);
    finishGather(build_.grid, rayCount, std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count(),
                 &build_.gridStats);
    const IlluminationGridView& hv = build_.grid.view();
    check(cudaMemcpy(const_cast<ShL1*>(gridView_.sh), hv.sh, size_t(n_) * sizeof(ShL1), cudaMemcpyHostToDevice),
          "uploading the grid");
    check(cudaMemcpy(const_cast<float*>(gridView_.weight), hv.weight, size_t(n_) * sizeof(float),
                     cudaMemcpyHostToDevice),
          "uploading the grid");
  }

  GridExecutorSettings s_;
  GridBuild build_;
  const SceneView* sceneView_ = nullptr;
  BvhTracer tracer_;
  IrradianceCacheView global_, caustic_;
  IlluminationGridView gridView_;  // device pointers
  int n_ = 0;
  ShL1* sums_ = nullptr;
  int* backs_ = nullptr;
  unsigned long long* rays_ = nullptr;
};

// The paper's basis: M directions a point, M RGB coefficients a point (DirectionalGridExecutor
// on the CPU). Each gather thread writes its point's M sums to its own slice of one buffer.
__global__ void directionalGatherKernel(const SceneView* sc, BvhTracer tracer, DirectionalGridView grid, ChainParams cp,
                                        IrradianceCacheView global, IrradianceCacheView caustic, uint32_t seed,
                                        int first, int samples, int length, int begin, int end, Color* sums, int* backs,
                                        unsigned long long* rayCount) {
  int i = begin + int(blockIdx.x * blockDim.x + threadIdx.x);
  if (i >= end) return;
  uint64_t r = 0;
  directionalPointGather(*sc, tracer, grid, size_t(i), cp, global, caustic, seed, first, samples, length,
                         sums + size_t(i) * size_t(grid.m), &backs[i], &r);
  atomicAdd(rayCount, (unsigned long long)r);
}

class CudaDirectionalGridExecutor final
    : public RefiningExecutor<CudaPassExecutor<GridSample<BvhTracer, DirectionalGridView>>> {
 public:
  CudaDirectionalGridExecutor(const Scene& scene, const Bvh& bvh, const GridExecutorSettings& s, int directions,
                              SampleSequence seq, int gpu, bool keepVariance)
      : s_(s) {
    grid_ = makeDirectionalGrid(scene, s.resolution, directions, s.seed);
    shootPhotons(scene, s.photons, &global_, &caustic_, &photonStats_);
    auto ds = std::make_unique<DeviceScene>(scene, bvh);
    DeviceArena& a = ds->arena;
    sceneView_ = ds->deviceView;
    tracer_ = BvhTracer{ds->bvh};
    globalView_ = uploadCache(a, global_.irradianceCache());
    causticView_ = uploadCache(a, caustic_.irradianceCache());
    n_ = grid_.pointCount();
    const DirectionalGridView& hv = grid_.view();
    const size_t coeffs = n_ * size_t(hv.m);
    sums_ = a.allocate<Color>(coeffs, "grid gather sums");
    backs_ = a.allocate<int>(n_, "grid gather sums");
    rays_ = a.allocate<unsigned long long>(1, "counters");
    view_ = hv;
    view_.dirs = a.upload(hv.dirs, size_t(hv.m), "grid directions");
    view_.share = a.upload(hv.share, size_t(hv.m), "grid directions");
    view_.coeff = a.allocate<Color>(coeffs, "directional grid");
    view_.weight = a.allocate<float>(n_, "directional grid");
    gather(0, directionalSamples(s.gatherRays, grid_.directions()));
    logPhotonStats(photonStats_);
    logDirectionalGrid(grid_, stats_);
    GridSample<BvhTracer, DirectionalGridView> sample{sceneView_, tracer_, view_, causticView_, s.params};
    camera_ = std::make_unique<CudaPassExecutor<GridSample<BvhTracer, DirectionalGridView>>>(
        std::move(ds), sample, scene.view().camera, seq, gpu, keepVariance);
  }

  size_t deviceBytes() const { return camera_->deviceBytes(); }

 private:
  void refine() override {
    const int done = grid_.samplesPerDirection(), add = directionalSamplesToAdd(s_, grid_.directions(), done);
    if (add > 0) gather(done, add);
  }

  // Samples [first, first + samples) of every direction of every point on the device; the host
  // adds them to the grid, averages, and uploads the coefficients and weights.
  void gather(int first, int samples) {
    auto t0 = std::chrono::steady_clock::now();
    check(cudaMemset(rays_, 0, sizeof(unsigned long long)), "clearing counters");
    const std::atomic<bool>* cancel = first == 0 ? s_.cancel : nullptr;
    const int length = directionalSequenceLength(s_, grid_.directions());
    const int n = int(n_), m = grid_.directions();
    // Fewer points a launch where each carries M directions: a launch stays milliseconds.
    const int perLaunch = std::max(kThreads, kPointsPerLaunch / std::max(1, m / 16));
    for (int begin = 0; begin < n; begin += perLaunch) {
      throwIfCancelled(cancel);
      const int end = std::min(n, begin + perLaunch);
      directionalGatherKernel<<<(end - begin + kThreads - 1) / kThreads, kThreads>>>(
          sceneView_, tracer_, view_, s_.params.chain, globalView_, causticView_, s_.seed, first, samples, length,
          begin, end, sums_, backs_, rays_);
      check(cudaGetLastError(), "launching the directional grid's gather kernel");
      if (cancel) check(cudaDeviceSynchronize(), "gathering into the grid");
    }
    throwIfCancelled(cancel);
    std::vector<Color> sums(n_ * size_t(m));
    std::vector<int> backs(n_);
    unsigned long long rayCount = 0;
    check(cudaMemcpy(sums.data(), sums_, sums.size() * sizeof(Color), cudaMemcpyDeviceToHost), "filling the grid");
    check(cudaMemcpy(backs.data(), backs_, n_ * sizeof(int), cudaMemcpyDeviceToHost), "filling the grid");
    check(cudaMemcpy(&rayCount, rays_, sizeof(rayCount), cudaMemcpyDeviceToHost), "filling the grid");
    for (size_t i = 0; i < n_; ++i) grid_.accumulate(i, &sums[i * size_t(m)], samples, backs[i]);
    grid_.finish();
    stats_.points = n_;
    stats_.rays += rayCount;
    stats_.seconds += std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    const DirectionalGridView& hv = grid_.view();
    check(cudaMemcpy(const_cast<Color*>(view_.coeff), hv.coeff, sums.size() * sizeof(Color), cudaMemcpyHostToDevice),
          "uploading the grid");
    check(cudaMemcpy(const_cast<float*>(view_.weight), hv.weight, n_ * sizeof(float), cudaMemcpyHostToDevice),
          "uploading the grid");
  }

  GridExecutorSettings s_;
  DirectionalGrid grid_;
  PhotonMap global_, caustic_;
  PhotonShootStats photonStats_;
  GridBuildStats stats_;
  const SceneView* sceneView_ = nullptr;
  BvhTracer tracer_;
  IrradianceCacheView globalView_, causticView_;
  DirectionalGridView view_;  // device pointers
  size_t n_ = 0;
  Color* sums_ = nullptr;
  int* backs_ = nullptr;
  unsigned long long* rays_ = nullptr;
};

}  // namespace

std::unique_ptr<PassExecutor> makeCudaDirectionalGridExecutor(const Scene& scene, const Bvh& bvh,
                                                              GridExecutorSettings s, int directions,
                                                              SampleSequence seq, int gpu, bool keepVariance,
                                                              size_t* deviceBytes) {
  selectDevice(gpu);
  if (!s.photons.tracer) s.photons.tracer = makeCudaPhotonTracer(scene, bvh, gpu, s.photons.maxDepth);
  auto ex = std::make_unique<CudaDirectionalGridExecutor>(scene, bvh, s, directions, seq, gpu, keepVariance);
  if (deviceBytes) *deviceBytes = ex->deviceBytes();
  return ex;
}

std::unique_ptr<PassExecutor> makeCudaGridExecutor(const Scene& scene, const Bvh& bvh, GridExecutorSettings s,
                                                   SampleSequence seq, int gpu, bool keepVariance,
                                                   size_t* deviceBytes) {
  selectDevice(gpu);
  if (!s.photons.tracer) s.photons.tracer = makeCudaPhotonTracer(scene, bvh, gpu, s.photons.maxDepth);
  auto ex = std::make_unique<CudaGridExecutor>(scene, bvh, s, seq, gpu, keepVariance);
  if (deviceBytes) *deviceBytes = ex->deviceBytes();
  return ex;
}

}  // namespace envgi::gpu
