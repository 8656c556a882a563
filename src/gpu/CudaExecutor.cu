#include "gpu/CudaExecutor.h"

#include <spdlog/spdlog.h>

#include <atomic>

#include "gpu/CudaPassExecutor.cuh"

namespace envgi::gpu {

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

std::pair<int, int> computeCapability(int gpu) {
  cudaDeviceProp p;
  if (cudaGetDeviceProperties(&p, gpu) != cudaSuccess) return {0, 0};
  return {p.major, p.minor};
}

bool hasMachineCodeFor(int major, int minor) {
  // nvcc's list of the virtual architectures compiled (e.g. 800,900); each comes with machine
  // code here (CMake's "80-real 90"), which runs on later minor versions of the same major.
  constexpr int archs[] = {__CUDA_ARCH_LIST__};
  for (int a : archs)
    if (a / 100 == major && a % 100 / 10 <= minor) return true;
  return false;
}

void selectDevice(int gpu) {
  std::string why;
  int n = deviceCount(&why);
  if (n == 0) throw std::runtime_error("no CUDA device: " + why);
  if (gpu < 0 || gpu >= n)
    throw std::runtime_error("--gpu " + std::to_string(gpu) + ": this machine has " + std::to_string(n) +
                             " CUDA device(s), numbered from 0");
  check(cudaSetDevice(gpu), "selecting the device");
  auto [major, minor] = computeCapability(gpu);
  static std::atomic<bool> warned{false};
  if (!hasMachineCodeFor(major, minor) && !warned.exchange(true))
    spdlog::warn("this envgi has no machine code for {} (sm_{}{}): the driver compiles its PTX at the first "
                 "launch, which takes seconds; rebuild with -DCMAKE_CUDA_ARCHITECTURES={}{}",
                 deviceName(gpu), major, minor, major, minor);
}

KernelOccupancy pathKernelOccupancy(int gpu) {
  selectDevice(gpu);
  auto kernel = regenKernel<SampleIntegrator<BvhTracer>>;
  cudaFuncAttributes a;
  check(cudaFuncGetAttributes(&a, kernel), "reading the render kernel's attributes");
  KernelOccupancy o;
  o.registers = a.numRegs;
  o.threadsPerBlock = kRegenBlock;
  o.blocksPerSM = regenBlocksPerSM<SampleIntegrator<BvhTracer>>();
  return o;
}

std::unique_ptr<PassExecutor> makeCudaExecutor(const Scene& scene, const Bvh& bvh, const KernelSettings& k, int gpu,
                                               bool keepVariance, size_t* deviceBytes) {
  selectDevice(gpu);
  auto ds = std::make_unique<DeviceScene>(scene, bvh);
  SampleIntegrator<BvhTracer> integ;
  integ.type = k.type;
  integ.path = k.path;
  integ.direct = k.direct;
  integ.scene = ds->deviceView;
  integ.tracer = BvhTracer{ds->bvh};
  auto ex = std::make_unique<CudaPassExecutor<SampleIntegrator<BvhTracer>>>(std::move(ds), integ, scene.view().camera,
                                                                            k.sequence, gpu, keepVariance,
                                                                            ShadeKindSet::of(scene.view()));
  if (deviceBytes) *deviceBytes = ex->deviceBytes();
  return ex;
}

}  // namespace envgi::gpu
