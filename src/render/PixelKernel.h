// The per-pixel body of a render pass, written once for the CPU executor and the CUDA kernel:
// a pixel's samples [s0, s1) traced by an integrator and added to the film. Plain data only.
#pragma once

#include "integrators/DirectIntegrator.h"
#include "integrators/PathIntegrator.h"
#include "sampling/Sampler.h"

namespace envgi {

// What a pass needs to address a sample: the sequence, its seed and the pixel count it spans.
struct SampleSequence {
  SamplerType type = SamplerType::Independent;
  uint32_t spp = 1;
  uint32_t seed = 0;
};

enum class SampleIntegratorType : int { Path = 0, Direct = 1 };

// path or direct over any tracer; the integrators themselves are the shared templates.
template <class Tracer>
struct SampleIntegrator {
  SampleIntegratorType type = SampleIntegratorType::Path;
  PathParams path;
  DirectParams direct;
  const SceneView* scene = nullptr;
  Tracer tracer;

  ENVGI_HD Color operator()(const Ray& ray, Sampler& smp, uint64_t* rays) const {
    return type == SampleIntegratorType::Direct ? directTrace(*scene, tracer, ray, smp, direct, rays)
                                                : pathTrace(*scene, tracer, ray, smp, path, rays);
  }
};

// What the path and direct kernels run with (Renderer's kernelSettings() fills it from a scene).
struct KernelSettings {
  SampleIntegratorType type = SampleIntegratorType::Path;
  PathParams path;
  DirectParams direct;
  SampleSequence sequence;
  int spp = 1;
};

// The film as the kernels see it: per-pixel sums of radiance and of squared luminance (the
// latter may be null), row-major.
struct FilmView {
  Color* sum = nullptr;
  double* sumSqLum = nullptr;
  int width = 0, height = 0;
};

struct PixelCounters {
  uint64_t rays = 0;
  uint64_t dropped = 0;  // NaN, infinite or negative samples, left out of the sums
};

// Samples [s0, s1) of pixel (x, y). The same (pixel, sample) gives the same sample on any device.
template <class Integrator>
ENVGI_HD void renderPixel(const Camera& cam, const SampleSequence& seq, const Integrator& integrate, int x, int y,
                          int s0, int s1, FilmView film, PixelCounters* counters) {
  Sampler smp;
  smp.type = seq.type;
  smp.spp = seq.spp;
  smp.seed = seq.seed;
  Color acc(0.f);
  double accSq = 0.0;
  size_t pixel = size_t(y) * size_t(cam.width) + size_t(x);
  for (int s = s0; s < s1; ++s) {
    smp.start(uint64_t(pixel), uint32_t(s));
    Vec2f off = sampleFilter(cam.filter, smp.get2D());
    Ray ray = cam.generateRay(float(x) + 0.5f + off.x, float(y) + 0.5f + off.y);
    Color L = integrate(ray, smp, &counters->rays);
    if (!isFiniteVec(L) || L.x < 0.f || L.y < 0.f || L.z < 0.f) {
      ++counters->dropped;
      continue;
    }
    acc += L;
    accSq += double(luminance(L)) * double(luminance(L));
  }
  film.sum[pixel] += acc;
  if (film.sumSqLum) film.sumSqLum[pixel] += accSq;
}

}  // namespace envgi
