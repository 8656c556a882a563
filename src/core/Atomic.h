// Relaxed atomic adds that compile for both host and device: SPPM's photon splats and the GPU's
// regenerated paths add into per-pixel sums from many threads, on the CPU and in CUDA kernels.
#pragma once

#include <cstdint>

#include "core/Common.h"

namespace envgi {

#if !defined(__CUDA_ARCH__)
// GCC/Clang's generic builtins work on float and double in C++17 too (nvcc's host pass),
// unlike std::atomic_ref.
template <class T>
inline void atomicAddByCas(T* p, T v) {
  T expected, desired;
  __atomic_load(p, &expected, __ATOMIC_RELAXED);
  desired = expected + v;
  while (!__atomic_compare_exchange(p, &expected, &desired, true, __ATOMIC_RELAXED, __ATOMIC_RELAXED))
    desired = expected + v;
}
#endif

ENVGI_INLINE void atomicAddRelaxed(float* p, float v) {
#if defined(__CUDA_ARCH__)
  atomicAdd(p, v);
#else
  atomicAddByCas(p, v);
#endif
}

ENVGI_INLINE void atomicAddRelaxed(double* p, double v) {
#if defined(__CUDA_ARCH__)
  atomicAdd(p, v);
#else
  atomicAddByCas(p, v);
#endif
}

ENVGI_INLINE void atomicAddRelaxed(uint32_t* p, uint32_t v) {
#if defined(__CUDA_ARCH__)
  atomicAdd(reinterpret_cast<unsigned int*>(p), v);
#else
  __atomic_fetch_add(p, v, __ATOMIC_RELAXED);
#endif
}

ENVGI_INLINE void atomicAddRelaxed(uint64_t* p, uint64_t v) {
#if defined(__CUDA_ARCH__)
  atomicAdd(reinterpret_cast<unsigned long long*>(p), static_cast<unsigned long long>(v));
#else
  __atomic_fetch_add(p, v, __ATOMIC_RELAXED);
#endif
}

// Adds v to *p and returns what *p held before: a place claimed in a queue by many threads.
ENVGI_INLINE int atomicFetchAddRelaxed(int* p, int v) {
#if defined(__CUDA_ARCH__)
  return atomicAdd(p, v);
#else
  return __atomic_fetch_add(p, v, __ATOMIC_RELAXED);
#endif
}

}  // namespace envgi
