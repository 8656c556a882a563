#include "gpu/CudaExecutor.h"

#include "gpu/DeviceScene.h"

namespace envgi::gpu {

namespace {

using Integrator = SampleIntegrator<BvhTracer>;

// One thread a pixel, running that pixel's samples of the pass: the CPU executor's body.
__global__ void passKernel(Integrator integ, Camera cam, SampleSequence seq, int s0, int s1, FilmView film,
                           unsigned long long* rays, unsigned long long* dropped) {
  int x = int(blockIdx.x * blockDim.x + threadIdx.x), y = int(blockIdx.y * blockDim.y + threadIdx.y);
  if (x >= cam.width || y >= cam.height) return;
  PixelCounters pc;
  renderPixel(cam, seq, integ, x, y, s0, s1, film, &pc);
  atomicAdd(rays, (unsigned long long)pc.rays);
  if (pc.dropped) atomicAdd(dropped, (unsigned long long)pc.dropped);
}

class CudaExecutor final : public PassExecutor {
 public:
  CudaExecutor(const Scene& scene, const Bvh& bvh, const KernelSettings& k, int gpu, bool keepVariance)
      : gpu_(gpu), scene_(scene, bvh), cam_(scene.view().camera), seq_(k.sequence) {
    integ_.type = k.type;
    integ_.path = k.path;
    integ_.direct = k.direct;
    integ_.scene = scene_.deviceView;
    integ_.tracer = BvhTracer{scene_.bvh};
    size_t px = size_t(cam_.width) * cam_.height;
    film_.width = cam_.width;
    film_.height = cam_.height;
    film_.sum = scene_.arena.allocate<Color>(px, "film");
    check(cudaMemset(film_.sum, 0, px * sizeof(Color)), "clearing the film");
    if (keepVariance) {
      film_.sumSqLum = scene_.arena.allocate<double>(px, "film variance");
      check(cudaMemset(film_.sumSqLum, 0, px * sizeof(double)), "clearing the film");
    }
    counters_ = scene_.arena.allocate<unsigned long long>(2, "counters");
    check(cudaMemset(counters_, 0, 2 * sizeof(unsigned long long)), "clearing counters");
  }
  size_t deviceBytes() const { return scene_.arena.bytes(); }

  std::string deviceName() const override { return "cuda:" + std::to_string(gpu_) + " (" + gpu::deviceName(gpu_) + ")"; }

  void runPass(int s0, int s1, Progress& progress, PassCounters* counters) override {
    dim3 block(16, 8);
    dim3 grid((cam_.width + 15) / 16, (cam_.height + 7) / 8);
    passKernel<<<grid, block>>>(integ_, cam_, seq_, s0, s1, film_, counters_, counters_ + 1);
    check(cudaGetLastError(), "launching the render kernel");
    check(cudaDeviceSynchronize(), "running the render kernel");
    unsigned long long c[2];
    check(cudaMemcpy(c, counters_, sizeof(c), cudaMemcpyDeviceToHost), "reading counters");
    check(cudaMemset(counters_, 0, sizeof(c)), "clearing counters");
    counters->rays += c[0];
    counters->dropped += c[1];
    progress.add(size_t(cam_.width) * cam_.height * size_t(s1 - s0));
  }

  void readFilm(FilmSums* out) override {
    size_t px = size_t(cam_.width) * cam_.height;
    out->sum.resize(px);
    check(cudaMemcpy(out->sum.data(), film_.sum, px * sizeof(Color), cudaMemcpyDeviceToHost), "reading the film");
    out->sumSqLum.clear();
    if (film_.sumSqLum) {
      out->sumSqLum.resize(px);
      check(cudaMemcpy(out->sumSqLum.data(), film_.sumSqLum, px * sizeof(double), cudaMemcpyDeviceToHost),
            "reading the film");
    }
  }

 private:
  int gpu_;
  DeviceScene scene_;
  Camera cam_;
  SampleSequence seq_;
  Integrator integ_;
  FilmView film_;
  unsigned long long* counters_ = nullptr;
};

}  // namespace

int deviceCount(std::string* why) {
  int n = 0;
  cudaError_t e = cudaGetDeviceCount(&n);
  if (e != cudaSuccess) {
    cudaGetLastError();
    if (why)
      *why = e == cudaErrorInsufficientDriver
                 ? "no NVIDIA driver, or one older than this build's CUDA runtime needs"
                 : std::string(cudaGetErrorString(e));
    return 0;
  }
  if (n == 0 && why) *why = "no CUDA device";
  return n;
}

std::string deviceName(int gpu) {
  cudaDeviceProp p;
  if (cudaGetDeviceProperties(&p, gpu) != cudaSuccess) return "unknown";
  return p.name;
}

void selectDevice(int gpu) {
  std::string why;
  int n = deviceCount(&why);
  if (n == 0) throw std::runtime_error("no CUDA device: " + why);
  if (gpu < 0 || gpu >= n)
    throw std::runtime_error("--gpu " + std::to_string(gpu) + ": this machine has " + std::to_string(n) +
                             " CUDA device(s), numbered from 0");
  check(cudaSetDevice(gpu), "selecting the device");
}

std::unique_ptr<PassExecutor> makeCudaExecutor(const Scene& scene, const Bvh& bvh, const KernelSettings& k, int gpu,
                                               bool keepVariance, size_t* deviceBytes) {
  selectDevice(gpu);
  auto ex = std::make_unique<CudaExecutor>(scene, bvh, k, gpu, keepVariance);
  if (deviceBytes) *deviceBytes = ex->deviceBytes();
  return ex;
}

}  // namespace envgi::gpu
