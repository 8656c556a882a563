// The film as every executor's stages see it, and what a sample must be to go into it.
#pragma once

#include <cstddef>
#include <cstdint>

#include "core/Vec.h"

namespace envgi {

// Per-pixel sums of radiance and of squared luminance (the latter may be null), row-major.
// Adaptive sampling (render/AdaptiveSampling.h) sets active: a pixel whose entry is 0 has
// converged and takes no more samples; null means every pixel is active.
struct FilmView {
  Color* sum = nullptr;
  double* sumSqLum = nullptr;
  int width = 0, height = 0;
  const unsigned char* active = nullptr;
  float* weightSum = nullptr;  // the filter's weights summed, for a filter with negative lobes
  ENVGI_HD bool takesSamples(size_t pixel) const { return !active || active[pixel] != 0; }
};

struct PixelCounters {
  uint64_t rays = 0;
  uint64_t dropped = 0;  // NaN, infinite or negative samples, left out of the sums
};

// Whether a sample's radiance goes into the film; NaN, infinite or negative ones are counted
// as dropped instead. It is asked of the radiance before the filter's weight, which may be
// negative, multiplies it.
ENVGI_HD inline bool acceptedSample(const Color& L, PixelCounters* counters) {
  if (isFiniteVec(L) && L.x >= 0.f && L.y >= 0.f && L.z >= 0.f) return true;
  ++counters->dropped;
  return false;
}

}  // namespace envgi
