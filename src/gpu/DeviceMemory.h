// Device memory owned in one place: every allocation of a CUDA render lives in a DeviceArena
// and is freed with it. Every CUDA error becomes a std::runtime_error naming what failed, so the
// command line prints one `envgi: error:` line. CUDA-only (included from .cu files).
#pragma once

#include <cuda_runtime.h>

#include <stdexcept>
#include <string>
#include <vector>

namespace envgi::gpu {

inline void check(cudaError_t e, const char* what) {
  if (e == cudaSuccess) return;
  cudaGetLastError();  // clear a non-sticky error so the process can still report and exit cleanly
  throw std::runtime_error(std::string("CUDA: ") + what + ": " + cudaGetErrorString(e));
}

class DeviceArena {
 public:
  DeviceArena() = default;
  DeviceArena(const DeviceArena&) = delete;
  DeviceArena& operator=(const DeviceArena&) = delete;
  ~DeviceArena() {
    for (void* p : blocks_) cudaFree(p);
  }

  void* allocate(size_t bytes, const char* what) {
    void* p = nullptr;
    if (bytes == 0) return nullptr;
    cudaError_t e = cudaMalloc(&p, bytes);
    if (e == cudaErrorMemoryAllocation) {
      cudaGetLastError();
      size_t freeB = 0, totalB = 0;
      cudaMemGetInfo(&freeB, &totalB);
      throw std::runtime_error("CUDA: out of device memory allocating " + std::to_string(bytes >> 20) + " MB for " +
                               what + " (" + std::to_string(freeB >> 20) + " MB free of " +
                               std::to_string(totalB >> 20) + " MB)");
    }
    check(e, what);
    blocks_.push_back(p);
    bytes_ += bytes;
    return p;
  }

  template <class T>
  T* allocate(size_t n, const char* what) {
    return static_cast<T*>(allocate(n * sizeof(T), what));
  }

  // A device copy of n host elements; null for n = 0 or a null source.
  template <class T>
  const T* upload(const T* host, size_t n, const char* what) {
    if (!host || n == 0) return nullptr;
    T* d = allocate<T>(n, what);
    check(cudaMemcpy(d, host, n * sizeof(T), cudaMemcpyHostToDevice), what);
    return d;
  }

  size_t bytes() const { return bytes_; }

 private:
  std::vector<void*> blocks_;
  size_t bytes_ = 0;
};

}  // namespace envgi::gpu
