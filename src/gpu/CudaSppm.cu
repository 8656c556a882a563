// SPPM on a CUDA GPU: each iteration runs integrators/Sppm.h's steps as kernels, one thread a
// pixel or a photon, over the scene and BVH that the path kernels use. The visible points'
// hashed grid is built on the device: keys per pixel, CUB's stable radix sort of (key, pixel),
// then the bucket starts per sorted position; the same arrays as the CPU's counting sort.
// Not bit-deterministic: photons add into a pixel's sums by float atomics in arrival order.
#include <cub/device/device_radix_sort.cuh>
#include <cub/device/device_reduce.cuh>

#include <chrono>
#include <cmath>
#include <cstring>

#include "gpu/CudaExecutor.h"
#include "gpu/DeviceScene.h"
#include "render/SppmPassExecutor.h"

namespace envgi::gpu {

namespace {

using Clock = std::chrono::steady_clock;

constexpr int kThreads = 128;
int blocksFor(size_t n) { return int((n + kThreads - 1) / kThreads); }

__global__ void __launch_bounds__(kThreads, kTracingThreadsPerSM / kThreads)
    cameraKernel(const SceneView* sc, BvhTracer tracer, SppmParams s, SppmPixels px, int n, int pass,
                 unsigned long long* rays) {
  int i = int(blockIdx.x * blockDim.x + threadIdx.x);
  if (i >= n) return;
  atomicAdd(rays, (unsigned long long)sppmCameraStep(*sc, tracer, s, px, i, pass));
}

// What the grid's size needs: each pixel's R^2 where its visible point is kept (else 0), and
// 1 where it is kept.
__global__ void keptKernel(SppmPixels px, int n, float* keptR2, int* kept) {
  int i = int(blockIdx.x * blockDim.x + threadIdx.x);
  if (i >= n) return;
  keptR2[i] = px.vpValid[i] ? px.r2[i] : 0.f;
  kept[i] = px.vpValid[i] ? 1 : 0;
}

__global__ void keysKernel(HashGridView g, SppmPixels px, int n, int* keys, int* index) {
  int i = int(blockIdx.x * blockDim.x + threadIdx.x);
  if (i >= n) return;
  keys[i] = g.key(px.vpPos[i], px.vpValid[i] != 0);
  index[i] = i;
}

__global__ void bucketStartKernel(const int* sortedKeys, int n, int tableSize, int* start) {
  int i = int(blockIdx.x * blockDim.x + threadIdx.x);
  if (i > n) return;
  hashGridBucketStarts(sortedKeys, n, tableSize, i, start);
}

__global__ void __launch_bounds__(kThreads, kTracingThreadsPerSM / kThreads)
    photonKernel(const SceneView* sc, BvhTracer tracer, PhotonEmitter emitter, SppmParams s,
                 SppmPixels px, HashGridView g, int pass, unsigned long long* hits) {
  uint64_t j = uint64_t(blockIdx.x) * blockDim.x + threadIdx.x;
  if (j >= s.photonsPerPass) return;
  uint32_t h = sppmPhotonStep(*sc, tracer, emitter, s, px, g, j, pass);
  if (h) atomicAdd(hits, (unsigned long long)h);
}

__global__ void updateKernel(SppmParams s, SppmPixels px, int n) {
  int i = int(blockIdx.x * blockDim.x + threadIdx.x);
  if (i < n) sppmUpdateStep(s, px, i);
}

int bitsFor(int v) {
  int b = 1;
  while (b < 31 && (1 << b) <= v) ++b;
  return b;
}

class CudaSppmExecutor final : public SppmPassExecutor {
 public:
  CudaSppmExecutor(const Scene& scene, const Bvh& bvh, const SppmParams& p, const PhotonEmitter& e, int gpu)
      : gpu_(gpu), scene_(scene, bvh), p_(p), emitter_(e), anyLight_(e.emitsLight(scene.view())),
        n_(scene.view().camera.width * scene.view().camera.height) {
    DeviceArena& a = scene_.arena;
    size_t n = size_t(n_);
    px_.vp = a.allocate<VisiblePoint>(n, "SPPM visible points");
    px_.vpPos = a.allocate<Vec3f>(n, "SPPM visible points");
    px_.vpValid = a.allocate<char>(n, "SPPM visible points");
    float r0 = sppmInitialRadius(p_, emitter_);
    std::vector<float> r2(n, r0 * r0);
    px_.r2 = const_cast<float*>(a.upload(r2.data(), n, "SPPM radii"));
    px_.n = a.allocate<float>(n, "SPPM photon counts");
    px_.phi = a.allocate<float>(3 * n, "SPPM flux");
    px_.m = a.allocate<uint32_t>(n, "SPPM photon counts");
    px_.tau = a.allocate<Color>(n, "SPPM flux");
    px_.ld = a.allocate<Color>(n, "SPPM direct light");
    check(cudaMemset(px_.vpValid, 0, n), "clearing SPPM state");
    check(cudaMemset(px_.n, 0, n * sizeof(float)), "clearing SPPM state");
    check(cudaMemset(px_.phi, 0, 3 * n * sizeof(float)), "clearing SPPM state");
    check(cudaMemset(px_.m, 0, n * sizeof(uint32_t)), "clearing SPPM state");
    check(cudaMemset(px_.tau, 0, n * sizeof(Color)), "clearing SPPM state");
    check(cudaMemset(px_.ld, 0, n * sizeof(Color)), "clearing SPPM state");
    if (scene.view().camera.filter.hasNegativeLobes()) {
      px_.weightSum = a.allocate<float>(n, "SPPM filter weights");
      check(cudaMemset(px_.weightSum, 0, n * sizeof(float)), "clearing SPPM state");
    }
    keptR2_ = a.allocate<float>(n, "SPPM grid");
    kept_ = a.allocate<int>(n, "SPPM grid");
    keys_[0] = a.allocate<int>(n, "SPPM grid");
    keys_[1] = a.allocate<int>(n, "SPPM grid");
    index_[0] = a.allocate<int>(n, "SPPM grid");
    index_[1] = a.allocate<int>(n, "SPPM grid");
    start_ = a.allocate<int>(size_t(hashGridTableSize(n)) + 1, "SPPM grid");
    reduced_ = a.allocate<float>(2, "SPPM grid");
    counters_ = a.allocate<unsigned long long>(2, "counters");
    check(cudaMemset(counters_, 0, 2 * sizeof(unsigned long long)), "clearing counters");
    // One scratch block for CUB, sized for the largest of its three calls.
    size_t sortBytes = 0, maxBytes = 0, sumBytes = 0;
    check(cub::DeviceRadixSort::SortPairs(nullptr, sortBytes, keys_[0], keys_[1], index_[0], index_[1], n_),
          "sizing the grid sort");
    check(cub::DeviceReduce::Max(nullptr, maxBytes, keptR2_, reduced_, n_), "sizing a reduction");
    check(cub::DeviceReduce::Sum(nullptr, sumBytes, kept_, reinterpret_cast<int*>(reduced_ + 1), n_),
          "sizing a reduction");
    tempBytes_ = std::max(sortBytes, std::max(maxBytes, sumBytes));
    temp_ = a.allocate(tempBytes_, "SPPM sort scratch");
  }

  std::string deviceName() const override { return "cuda:" + std::to_string(gpu_) + " (" + gpu::deviceName(gpu_) + ")"; }
  size_t deviceBytes() const { return scene_.arena.bytes(); }

  void runPass(int s0, int s1, Progress& progress, PassCounters* counters) override {
    for (int pass = s0; pass < s1; ++pass) {
      iteration(pass, counters);
      progress.add(size_t(n_));
    }
  }

  void readFilm(FilmSums* out) override {
    size_t n = size_t(n_);
    std::vector<Color> ld(n), tau(n);
    std::vector<float> r2(n);
    check(cudaMemcpy(ld.data(), px_.ld, n * sizeof(Color), cudaMemcpyDeviceToHost), "reading the film");
    check(cudaMemcpy(tau.data(), px_.tau, n * sizeof(Color), cudaMemcpyDeviceToHost), "reading the film");
    check(cudaMemcpy(r2.data(), px_.r2, n * sizeof(float), cudaMemcpyDeviceToHost), "reading the film");
    int passes = std::max(st_.passesDone, 1);
    double photons = double(std::max<uint64_t>(st_.photonsShot, 1));
    out->sum.resize(n);
    out->sumSqLum.clear();
    for (size_t i = 0; i < n; ++i) out->sum[i] = sppmRadiance(ld[i], tau[i], r2[i], passes, photons) * float(passes);
    out->weightSum.clear();
    if (px_.weightSum) {
      out->weightSum.resize(n);
      check(cudaMemcpy(out->weightSum.data(), px_.weightSum, n * sizeof(float), cudaMemcpyDeviceToHost),
            "reading the film");
    }
  }

  SppmStats stats() const override {
    SppmStats s = st_;
    std::vector<float> r2(static_cast<size_t>(n_));
    check(cudaMemcpy(r2.data(), px_.r2, r2.size() * sizeof(float), cudaMemcpyDeviceToHost), "reading radii");
    double rs = 0.0;
    for (float v : r2) rs += std::sqrt(v);
    s.meanRadius = float(rs / double(std::max(n_, 1)));
    s.bytes = scene_.arena.bytes();
    return s;
  }

 private:
  void iteration(int pass, PassCounters* counters) {
    auto tc = Clock::now();
    const int n = n_;
    BvhTracer tracer{scene_.bvh};
    cameraKernel<<<blocksFor(size_t(n)), kThreads>>>(scene_.deviceView, tracer, p_, px_, n, pass, counters_);
    check(cudaGetLastError(), "launching the SPPM camera kernel");
    HashGridView g = buildGrid();
    check(cudaDeviceSynchronize(), "running the SPPM camera kernel");
    auto tp = Clock::now();
    st_.cameraSeconds += std::chrono::duration<double>(tp - tc).count();
    if (anyLight_ && g.tableSize > 0) {
      photonKernel<<<blocksFor(p_.photonsPerPass), kThreads>>>(scene_.deviceView, tracer, emitter_, p_, px_, g, pass,
                                                               counters_ + 1);
      check(cudaGetLastError(), "launching the SPPM photon kernel");
    }
    updateKernel<<<blocksFor(size_t(n)), kThreads>>>(p_, px_, n);
    check(cudaGetLastError(), "launching the SPPM update kernel");
    unsigned long long c[2];
    check(cudaMemcpy(c, counters_, sizeof(c), cudaMemcpyDeviceToHost), "running the SPPM photon pass");
    check(cudaMemset(counters_, 0, sizeof(c)), "clearing counters");
    st_.photonSeconds += std::chrono::duration<double>(Clock::now() - tp).count();
    st_.photonsShot += p_.photonsPerPass;
    st_.passesDone = pass + 1;
    st_.photonHits += c[1];
    st_.rays += c[0];
    counters->rays += c[0];
  }

  // The visible points' grid: cell size the largest kept radius, twice as many buckets as kept
  // points (as the CPU's HashGrid). tableSize 0 when no point is kept.
  HashGridView buildGrid() {
    const int n = n_;
    keptKernel<<<blocksFor(size_t(n)), kThreads>>>(px_, n, keptR2_, kept_);
    check(cudaGetLastError(), "launching the SPPM grid kernels");
    size_t bytes = tempBytes_;
    check(cub::DeviceReduce::Max(temp_, bytes, keptR2_, reduced_, n), "sizing the SPPM grid");
    bytes = tempBytes_;
    check(cub::DeviceReduce::Sum(temp_, bytes, kept_, reinterpret_cast<int*>(reduced_ + 1), n), "sizing the SPPM grid");
    float r[2];
    check(cudaMemcpy(r, reduced_, sizeof(r), cudaMemcpyDeviceToHost), "sizing the SPPM grid");
    int keptCount;
    std::memcpy(&keptCount, &r[1], sizeof(int));
    HashGridView g;
    if (keptCount == 0) {
      g.tableSize = 0;
      return g;
    }
    g.tableSize = hashGridTableSize(size_t(keptCount));
    g.cellSize = std::sqrt(std::max(r[0], 1e-12f));
    keysKernel<<<blocksFor(size_t(n)), kThreads>>>(g, px_, n, keys_[0], index_[0]);
    check(cudaGetLastError(), "launching the SPPM grid kernels");
    bytes = tempBytes_;
    check(cub::DeviceRadixSort::SortPairs(temp_, bytes, keys_[0], keys_[1], index_[0], index_[1], n, 0,
                                          bitsFor(g.tableSize)),
          "sorting the SPPM grid");
    bucketStartKernel<<<blocksFor(size_t(n) + 1), kThreads>>>(keys_[1], n, g.tableSize, start_);
    check(cudaGetLastError(), "launching the SPPM grid kernels");
    g.bucketStart = start_;
    g.items = index_[1];
    return g;
  }

  int gpu_;
  DeviceScene scene_;
  SppmParams p_;
  PhotonEmitter emitter_;
  bool anyLight_;
  int n_;
  SppmPixels px_;
  float* keptR2_ = nullptr;
  int* kept_ = nullptr;
  int* keys_[2] = {nullptr, nullptr};
  int* index_[2] = {nullptr, nullptr};
  int* start_ = nullptr;
  float* reduced_ = nullptr;
  unsigned long long* counters_ = nullptr;
  void* temp_ = nullptr;
  size_t tempBytes_ = 0;
  SppmStats st_;
};

}  // namespace

std::unique_ptr<PassExecutor> makeCudaSppmExecutor(const Scene& scene, const Bvh& bvh, const SppmParams& params,
                                                   const PhotonEmitter& emitter, int gpu, size_t* deviceBytes) {
  checkSppmParams(params);  // before anything is uploaded
  selectDevice(gpu);
  auto ex = std::make_unique<CudaSppmExecutor>(scene, bvh, params, emitter, gpu);
  if (deviceBytes) *deviceBytes = ex->deviceBytes();
  return ex;
}

}  // namespace envgi::gpu
