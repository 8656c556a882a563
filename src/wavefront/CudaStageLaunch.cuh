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

template <class Stage>
__global__ void __launch_bounds__(kStageBlock, kStageBlocksPerSM) stageKernel(Stage stage, int n, const int* count) {
  const int i = int(blockIdx.x * blockDim.x + threadIdx.x);
  if (i >= n || (count && i >= *count)) return;
  stage(i);
}

struct CudaStageLaunch {
  template <class Stage>
  void operator()(const Stage& stage, int n, const int* count) const {
    if (n <= 0) return;
    stageKernel<<<(n + kStageBlock - 1) / kStageBlock, kStageBlock>>>(stage, n, count);
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
