// A piecewise-constant density on [0,1] sampled by inverting its CDF with binary search
// (steps 3, 5 and 7-8 of the paper's Algorithm 1).
#pragma once

#include <vector>

#include "core/Common.h"

namespace envgi {

// The largest i in [lo, hi] with cdf[i] <= u (lo if none), for a non-decreasing cdf.
ENVGI_INLINE int findIntervalBetween(const float* cdf, int lo, int hi, float u) {
  while (lo < hi) {
    int mid = (lo + hi + 1) >> 1;
    if (cdf[mid] <= u) lo = mid;
    else hi = mid - 1;
  }
  return lo;
}

// The same answer without branches: it lies in [base, base + n), and each step halves n and
// moves base by a conditional move. For the short ranges a guide table leaves, where which way a
// random u goes is a coin flip that a branch mispredicts (product sampling: 124 -> 100 ns,
// BM_Sample/6). Over a whole large cdf the branches win: their speculation fetches ahead.
ENVGI_INLINE int findIntervalBetweenNoBranch(const float* cdf, int lo, int hi, float u) {
  const float* base = cdf + lo;
  for (int n = hi - lo + 1; n > 1;) {
    int half = n >> 1;
    base = base[half] <= u ? base + half : base;
    n -= half;
  }
  return int(base - cdf);
}

// Index i in [0, size-2] with cdf[i] <= u < cdf[i+1], for a non-decreasing cdf.
ENVGI_INLINE int findInterval(const float* cdf, int size, float u) { return findIntervalBetween(cdf, 0, size - 2, u); }

// findInterval narrowed by a guide table (Chen and Asau's cutpoints): guide[g] is the index for
// u = g / G, g in [0, G], with G a power of two so that g / G and u * G are exact in float.
// The index is non-decreasing in u, so the answer for u lies in [guide[g], guide[g + 1]] with
// g = floor(u G): the same index as the plain search, from a few loads instead of log2(size).
// guideSlot(u, G) is that g.
ENVGI_INLINE int guideSlot(float u, int G) {
  int g = int(u * float(G));
  return g < 0 ? 0 : (g > G - 1 ? G - 1 : g);
}
ENVGI_INLINE int findIntervalGuided(const float* cdf, float u, const int* guide, int G) {
  const int g = guideSlot(u, G);
  return findIntervalBetweenNoBranch(cdf, guide[g], guide[g + 1], u);
}

// Fills guide[0..G] for findIntervalGuided; G must be a power of two.
void buildGuide(const float* cdf, int size, int G, int* guide);

// The guide size for a cdf over n intervals: about one guide entry per `perEntry` intervals.
int guideSize(int n, int perEntry);

// Plain view over storage owned elsewhere (host vectors now, device buffers on the GPU).
// A function that is zero everywhere degenerates to the uniform density, so sampling a
// zero-power light never divides by zero.
struct PiecewiseConstant1DView {
  const float* func = nullptr;  // n values, non-negative
  const float* cdf = nullptr;   // n + 1 values, cdf[0] = 0, cdf[n] = 1
  int n = 0;
  float funcInt = 0.f;  // integral of func over [0,1]

  ENVGI_HD float pdf(float x) const {
    int i = clampi(int(x * n), 0, n - 1);
    return funcInt > 0.f ? func[i] / funcInt : 1.f;
  }
  ENVGI_HD float discretePmf(int i) const { return cdf[i + 1] - cdf[i]; }

  // Returns x in [0,1); *pdf is the continuous density there, *offset the cell index.
  ENVGI_HD float sample(float u, float* pdfOut, int* offset) const {
    int i = findInterval(cdf, n + 1, u);
    float width = cdf[i + 1] - cdf[i];
    float du = width > 0.f ? (u - cdf[i]) / width : 0.5f;
    if (pdfOut) *pdfOut = funcInt > 0.f ? func[i] / funcInt : 1.f;
    if (offset) *offset = i;
    float x = (float(i) + du) / float(n);
    return x < kOneMinusEpsilon ? x : kOneMinusEpsilon;
  }

  // Inverse of sample(): the u that maps to x.
  ENVGI_HD float invert(float x) const {
    int i = clampi(int(x * n), 0, n - 1);
    float t = x * n - float(i);
    return lerpf(t, cdf[i], cdf[i + 1]);
  }
};

class PiecewiseConstant1D {
 public:
  PiecewiseConstant1D() = default;
  explicit PiecewiseConstant1D(const float* f, int n) { build(f, n, func_, cdf_, funcInt_); }
  explicit PiecewiseConstant1D(const std::vector<float>& f) : PiecewiseConstant1D(f.data(), int(f.size())) {}

  PiecewiseConstant1DView view() const { return {func_.data(), cdf_.data(), int(func_.size()), funcInt_}; }
  float integral() const { return funcInt_; }
  int size() const { return int(func_.size()); }

  // Builds func/cdf into the given arrays; shared with PiecewiseConstant2D's flat storage.
  static void build(const float* f, int n, float* funcOut, float* cdfOut, float* intOut);
  static void build(const float* f, int n, std::vector<float>& funcOut, std::vector<float>& cdfOut, float& intOut) {
    funcOut.resize(n);
    cdfOut.resize(n + 1);
    build(f, n, funcOut.data(), cdfOut.data(), &intOut);
  }

 private:
  std::vector<float> func_, cdf_;
  float funcInt_ = 0.f;
};

}  // namespace envgi
