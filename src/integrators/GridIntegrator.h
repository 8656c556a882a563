// The paper's interactive method as an integrator (`grid`): camera paths follow mirrors and
// glass to the first diffuse-like surface, which gets direct light from the map (Algorithm 1,
// shadow rays, MIS) and indirect light from the illumination grid, trilinearly interpolated,
// times its albedo / pi. The grid's points are filled by gatherRay: rays from each point
// that read the photon maps' precomputed irradiance one bounce away. Host and device.
#pragma once

#include "integrators/GatherHit.h"
#include "integrators/SpecularChain.h"
#include "photon/IlluminationGrid.h"
#include "photon/IrradianceCache.h"
#include "sampling/Warp.h"

namespace envgi {

struct GridParams {
  ChainParams chain;
};

// causticIrradiance(p, n) -> Color: irradiance by light that came through mirrors and glass
// (the caustic photon map's precomputed irradiance on the CPU).
template <class Tracer, class CausticIrradiance>
ENVGI_HD Color gridTrace(const SceneView& sc, const Tracer& tracer, const Ray& ray, Sampler& smp,
                         const IlluminationGridView& grid, const CausticIrradiance& causticIrradiance,
                         const GridParams& gp, uint64_t* rays) {
  auto estimate = [&](const SurfaceInteraction& si, Vec3f wo, Sampler&, uint64_t*) {
    const Bsdf& bsdf = sc.bsdfAt(si.bsdf, si.uv);
    // A one-sided reflector seen from behind reflects nothing, as the BSDF's own eval says.
    if (!bsdf.twoSided && !bsdfTransmits(bsdf) && dot(si.shading.n, wo) <= 0.f) return Color(0.f);
    Vec3f n = faceForward(si.shading.n, wo);
    Color E = grid.irradiance(si.p, n) + causticIrradiance(si.p, faceForward(si.ng, wo));
    return diffuseAlbedo(bsdf) * kInvPi * E;
  };
  return traceSpecularChain(sc, tracer, ray, smp, gp.chain, estimate, rays);
}

// Rays [first, first + rays) of grid point i at p: radiance gathered by gatherRay, projected
// on L1 SH (*sum, Monte Carlo over the sphere); *back counts rays whose first hit was a back
// face. Each point has its own Sobol sequence of `length` rays (the most it will ever get), so
// rays cover the sphere evenly and later calls refine the same estimate.
template <class Tracer>
ENVGI_HD void gridPointGather(const SceneView& sc, const Tracer& tracer, Vec3f p, uint64_t i, const ChainParams& cp,
                              const IrradianceCacheView& global, const IrradianceCacheView& caustic, uint32_t seed,
                              int first, int rays, int length, ShL1* sum, int* back, uint64_t* rayCount) {
  auto hitRadiance = [&](const SurfaceInteraction& si, Vec3f wi, Sampler& smp, uint64_t* r) {
    return gatherHitRadiance(sc, tracer, si, wi, smp, cp.strategy, global, caustic, r);
  };
  Sampler smp;
  smp.type = SamplerType::Sobol;
  smp.spp = uint32_t(length);
  smp.seed = seed ^ kGridGatherStream;
  *sum = ShL1{};
  *back = 0;
  for (int k = first; k < first + rays; ++k) {
    smp.start(i, uint32_t(k));
    Vec3f d = sampleUniformSphere(smp.get2D());
    bool isBack = false;
    Color L = gatherRay(sc, tracer, Ray{p, d, INFINITY}, smp, cp, hitRadiance, &isBack, rayCount);
    *back += isBack;
    if (!isFiniteVec(L)) continue;
    float y[4];
    shL1Basis(d, y);
    for (int c = 0; c < 4; ++c) sum->c[c] += L * (y[c] / uniformSpherePdf());
  }
}

// The SH grid's camera path (gridSample's choice for an IlluminationGridView).
template <class Tracer, class CausticIrradiance>
ENVGI_HD Color gridSample(const SceneView& sc, const Tracer& tracer, const Ray& ray, Sampler& smp,
                          const IlluminationGridView& grid, const CausticIrradiance& caustics, const GridParams& gp,
                          uint64_t* rays) {
  return gridTrace(sc, tracer, ray, smp, grid, caustics, gp, rays);
}

// One camera sample of the grid integrator, on either device: caustics from the caustic map's
// precomputed irradiance, the rest from the grid, of either basis (GridView: the SH grid's
// IlluminationGridView, or the paper's DirectionalGridView).
template <class Tracer, class GridView = IlluminationGridView>
struct GridSample {
  const SceneView* scene = nullptr;
  Tracer tracer;
  GridView grid;
  IrradianceCacheView caustic;
  GridParams params;
  ENVGI_HD Color operator()(const Ray& ray, Sampler& smp, uint64_t* rays) const {
    auto caustics = [&](Vec3f p, Vec3f n) { return caustic.irradiance(p, n); };
    return gridSample(*scene, tracer, ray, smp, grid, caustics, params, rays);
  }
};

}  // namespace envgi
