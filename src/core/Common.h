// Shared definitions for code that compiles for both host and CUDA device.
#pragma once

#include <cmath>
#include <cstdint>

#if defined(__CUDACC__)
#define ENVGI_HD __host__ __device__
#define ENVGI_INLINE __host__ __device__ __forceinline__
// Host and device, and one copy on the device: for rare, long paths that every kernel would
// otherwise inline (Beckmann's sampling loop), which grows every GPU binary.
#define ENVGI_HD_NOINLINE __host__ __device__ __noinline__
#else
#define ENVGI_HD
// Forced, as nvcc forces it: GCC left normalize() and its like as calls in the per-ray loop
// (7% of a depth-1 render in perf); forced, the bench's depth-1 render takes 0.86x the time.
#define ENVGI_INLINE inline __attribute__((always_inline))
#define ENVGI_HD_NOINLINE
#endif

namespace envgi {

constexpr float kPi = 3.14159265358979323846f;
constexpr float kInvPi = 0.31830988618379067154f;
constexpr float kInv2Pi = 0.15915494309189533577f;
constexpr float kInv4Pi = 0.07957747154594766788f;
constexpr float kOneMinusEpsilon = 0x1.fffffep-1f;

ENVGI_INLINE float clampf(float x, float lo, float hi) { return x < lo ? lo : (x > hi ? hi : x); }
ENVGI_INLINE int clampi(int x, int lo, int hi) { return x < lo ? lo : (x > hi ? hi : x); }
ENVGI_INLINE float lerpf(float t, float a, float b) { return (1.f - t) * a + t * b; }
ENVGI_INLINE float sqr(float x) { return x * x; }
ENVGI_INLINE float safeSqrt(float x) { return std::sqrt(x > 0.f ? x : 0.f); }
ENVGI_INLINE float safeAcos(float x) { return std::acos(clampf(x, -1.f, 1.f)); }

// Asks for the cache line at p (CPU only). An asm statement: with -O3, GCC 12 left out the
// __builtin_prefetch of loops that only prefetch (the photon pass's, the batch's vertices).
inline void prefetchLine(const void* p) {
#if defined(__x86_64__)
  asm volatile("prefetcht0 %0" : : "m"(*static_cast<const char*>(p)));
#else
  __builtin_prefetch(p);
#endif
}

// BT.709 luminance, the weighting the paper uses for its monochrome map (Section 2.2).
ENVGI_INLINE float luminance(float r, float g, float b) {
  return 0.2126f * r + 0.7152f * g + 0.0722f * b;
}

}  // namespace envgi
