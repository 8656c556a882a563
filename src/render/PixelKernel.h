// The per-sample bodies of a render pass as whole samples: a pixel's samples [s0, s1) traced
// by an integrator (renderPixel, the reference the wavefront is tested against) and the GPU's
// path regeneration. Plain data only; written once for the CPU and the CUDA kernels.
#pragma once

#include <vector>

#include "core/Atomic.h"
#include "wavefront/FilmView.h"
#include "wavefront/SampleIntegrator.h"
#include "wavefront/SampleSequence.h"

namespace envgi {

// What the path and direct kernels run with (Renderer's kernelSettings() fills it from a scene).
struct KernelSettings {
  SampleIntegratorType type = SampleIntegratorType::Path;
  PathParams path;
  DirectParams direct;
  SampleSequence sequence;
  int spp = 1;
};

// Samples [s0, s1) of pixel (x, y).
template <class Integrator>
ENVGI_HD void renderPixel(const Camera& cam, const SampleSequence& seq, const Integrator& integrate, int x, int y,
                          int s0, int s1, FilmView film, PixelCounters* counters) {
  size_t pixel = size_t(y) * size_t(cam.width) + size_t(x);
  if (!film.takesSamples(pixel)) return;
  Sampler smp = sequenceSampler(seq);
  Color acc(0.f);
  double accSq = 0.0;
  float accW = 0.f;
  for (int s = s0; s < s1; ++s) {
    float w;
    Color L = integrate(startCameraSample(cam, smp, x, y, s, &w), smp, &counters->rays);
    if (!acceptedSample(L, counters)) continue;
    L *= w;
    acc += L;
    accSq += double(luminance(L)) * double(luminance(L));
    accW += w;
  }
  film.sum[pixel] += acc;
  if (film.sumSqLum) film.sumSqLum[pixel] += accSq;
  if (film.weightSum) film.weightSum[pixel] += accW;
}

// Samples [s0, s1) of every pixel by path regeneration (Novak et al. 2010), for a GPU thread:
// whenever its path ends, the thread takes the next (pixel, sample) from fetch() (items numbered
// sample-major, so a warp's fresh items are neighbouring pixels) instead of idling while its
// warp's longest path finishes. Any thread may finish any pixel's sample, so the film sums are
// added atomically. With one thread and a counting fetch it adds each pixel's samples in the
// order renderPixel does, so a fresh film gets the same sums bit for bit.
template <class Integrator, class Fetch>
ENVGI_HD void regeneratePaths(const Camera& cam, const SampleSequence& seq, const Integrator& integ, int s0, int s1,
                              FilmView film, Fetch fetch, PixelCounters* counters) {
  const uint64_t npix = uint64_t(cam.width) * uint64_t(cam.height), total = npix * uint64_t(s1 - s0);
  Sampler smp = sequenceSampler(seq);
  PathState st = integ.begin(Ray{});
  uint64_t pixel = 0;
  float w = 1.f;
  bool active = false;
  for (;;) {
    if (!active) {
      uint64_t item = fetch();
      if (item >= total) break;
      pixel = item % npix;
      if (!film.takesSamples(pixel)) continue;  // converged: its item costs one fetch
      int x = int(pixel % uint64_t(cam.width)), y = int(pixel / uint64_t(cam.width));
      st = integ.begin(startCameraSample(cam, smp, x, y, s0 + int(item / npix), &w));
    }
    active = integ.step(&st, smp, &counters->rays);
    if (!active && acceptedSample(st.L, counters)) {
      st.L *= w;
      if (film.weightSum) atomicAddRelaxed(&film.weightSum[pixel], w);
      atomicAddRelaxed(&film.sum[pixel].x, st.L.x);
      atomicAddRelaxed(&film.sum[pixel].y, st.L.y);
      atomicAddRelaxed(&film.sum[pixel].z, st.L.z);
      if (film.sumSqLum) atomicAddRelaxed(&film.sumSqLum[pixel], double(luminance(st.L)) * double(luminance(st.L)));
    }
  }
}

}  // namespace envgi
