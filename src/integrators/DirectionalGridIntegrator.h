// The paper's grid read and filled (Section 3, steps 1-3 and 5), host and device: a grid point
// gathers the indirect radiance arriving along each of the grid's M directions (gatherRay, as
// the SH grid's rays do: what a direction meets is that surface's radiance, direct light there
// plus the photon maps), and a camera path follows mirrors and glass to the first rough surface,
// which gets direct light with shadows (the chain's next-event estimation, the collapsed map
// under `points`) plus sum_k f(w_k, wo) c_k(p), the coefficients interpolated trilinearly.
#pragma once

#include "integrators/GatherHit.h"
#include "integrators/GridIntegrator.h"
#include "photon/DirectionalGrid.h"

namespace envgi {

// `samples` more samples of every direction at grid point i (p): *sums gets m colours, each the
// radiance along direction k times its share, summed; *back counts rays that met a back face.
// Sample s of direction k is Sobol point s of stream i * m + k, so refinement continues them.
template <class Tracer>
ENVGI_HD void directionalPointGather(const SceneView& sc, const Tracer& tracer, const DirectionalGridView& g, size_t i,
                                     const ChainParams& cp, const IrradianceCacheView& global,
                                     const IrradianceCacheView& caustic, uint32_t seed, int first, int samples,
                                     int length, Color* sums, int* back, uint64_t* rayCount) {
  auto hitRadiance = [&](const SurfaceInteraction& si, Vec3f wi, Sampler& smp, uint64_t* r) {
    return gatherHitRadiance(sc, tracer, si, wi, smp, cp.strategy, global, caustic, r);
  };
  const Vec3f p = g.point(i);
  Sampler smp;
  smp.type = SamplerType::Sobol;
  smp.spp = uint32_t(length);
  smp.seed = seed ^ kGridGatherStream;
  *back = 0;
  for (int k = 0; k < g.m; ++k) {
    sums[k] = Color(0.f);
    for (int s = first; s < first + samples; ++s) {
      smp.start(uint64_t(i) * uint64_t(g.m) + uint64_t(k), uint32_t(s));
      bool isBack = false;
      Color L = gatherRay(sc, tracer, Ray{p, g.dirs[k], INFINITY}, smp, cp, hitRadiance, &isBack, rayCount);
      *back += isBack;
      if (isFiniteVec(L)) sums[k] += L * g.share[k];
    }
  }
}

// One camera sample: every rough surface (glossy ones too: each pixel's BSDF is applied per
// direction, so the threshold that sends sharp lobes down the chain is 0) reads the grid.
template <class Tracer, class CausticIrradiance>
ENVGI_HD Color directionalGridTrace(const SceneView& sc, const Tracer& tracer, const Ray& ray, Sampler& smp,
                                    const DirectionalGridView& grid, const CausticIrradiance& causticIrradiance,
                                    const GridParams& gp, uint64_t* rays) {
  auto estimate = [&](const SurfaceInteraction& si, Vec3f wo, Sampler&, uint64_t*) {
    BsdfScratch textured;
    const Bsdf& bsdf = sc.bsdfAt(si, &textured);
    if (!bsdf.twoSided && !bsdfTransmits(bsdf) && dot(si.shading.n, wo) <= 0.f) return Color(0.f);
    const GridCorners c = grid.corners(si.p, faceForward(si.shading.n, wo));
    const Vec3f woLocal = si.shading.toLocal(wo);
    Color L(0.f);
    for (int k = 0; k < grid.m; ++k) {
      float pdf;
      const Color f = bsdfEvalPdf(bsdf, woLocal, si.shading.toLocal(grid.dirs[k]), &pdf);
      if (!isBlack(f)) L += f * grid.at(c, k);
    }
    return L + diffuseAlbedo(bsdf) * kInvPi * causticIrradiance(si.p, faceForward(si.ng, wo));
  };
  ChainParams cp = gp.chain;
  cp.glossyThreshold = 0.f;
  return traceSpecularChain(sc, tracer, ray, smp, cp, estimate, rays);
}

// The paper's grid's camera path (GridSample's choice for a DirectionalGridView).
template <class Tracer, class CausticIrradiance>
ENVGI_HD Color gridSample(const SceneView& sc, const Tracer& tracer, const Ray& ray, Sampler& smp,
                          const DirectionalGridView& grid, const CausticIrradiance& caustics, const GridParams& gp,
                          uint64_t* rays) {
  return directionalGridTrace(sc, tracer, ray, smp, grid, caustics, gp, rays);
}

}  // namespace envgi
