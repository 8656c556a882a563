// The wave stages' launcher on a CUDA GPU (WavePass.h's Launch): a kernel a stage, a thread an
// index of its queue, the queues in device memory. CUDA only.
#pragma once

#include <cuda_runtime.h>

#include <stdexcept>
#include <string>

#include "wavefront/WaveStages.h"

namespace envgi {

constexpr int kStageBlock = 128;
// 8 blocks of 128 threads an SM: at most 64 registers a thread in every stage kernel.
constexpr int kStageBlocksPerSM = 8;
// 4 for the shade stages where asked (wideShade): up to 128 registers, where no material's code
// spills (docs/gpu.md), at half the resident threads. Which wins is a device's to measure.
constexpr int kWideStageBlocksPerSM = 4;

template <class Stage>
__device__ inline void runStageAt(const Stage& stage, int n, const int* count) {
  const int i = int(blockIdx.x * blockDim.x + threadIdx.x);
  if (i >= n || (count && i >= *count)) return;
  stage(i);
}
template <class Stage>
__global__ void __launch_bounds__(kStageBlock, kStageBlocksPerSM) stageKernel(Stage stage, int n, const int* count) {
  runStageAt(stage, n, count);
}
template <class Stage>
__global__ void __launch_bounds__(kStageBlock, kWideStageBlocksPerSM)
    wideStageKernel(Stage stage, int n, const int* count) {
  runStageAt(stage, n, count);
}

template <class Stage>
struct IsShadeStage {
  static constexpr bool value = false;
};
template <class I, int K>
struct IsShadeStage<ShadeStage<I, K>> {
  static constexpr bool value = true;
};

struct CudaStageLaunch {
  bool wideShade = false;  // the shade stages at kWideStageBlocksPerSM
  template <class Stage>
  void operator()(const Stage& stage, int n, const int* count) const {
    if (n <= 0) return;
    const int blocks = (n + kStageBlock - 1) / kStageBlock;
    bool wide = false;
    if constexpr (IsShadeStage<Stage>::value) {
      wide = wideShade;
      if (wide) wideStageKernel<<<blocks, kStageBlock>>>(stage, n, count);
    }
    if (!wide) stageKernel<<<blocks, kStageBlock>>>(stage, n, count);
    ok(cudaGetLastError(), "launching a wave stage");
  }
  template <class T>
  void write(T* to, const T& v) const {
    ok(cudaMemcpy(to, &v, sizeof(T), cudaMemcpyHostToDevice), "setting a wave's counts");
  }
  template <class T>
  T read(const T* from) const {
    T v;
    ok(cudaMemcpy(&v, from, sizeof(T), cudaMemcpyDeviceToHost), "running a wave's stages");
    return v;
  }
  void zero(void* p, size_t bytes) const { ok(cudaMemset(p, 0, bytes), "clearing a pass's sums"); }

  static void ok(cudaError_t e, const char* what) {
    if (e != cudaSuccess) throw std::runtime_error(std::string("CUDA error ") + what + ": " + cudaGetErrorString(e));
  }
};

}  // namespace envgi
