// The paper's interactive method as an integrator (`grid`): camera paths follow mirrors and
// glass to the first diffuse-like surface, which gets direct light from the map (Algorithm 1,
// shadow rays, MIS) and indirect light from the illumination grid, trilinearly interpolated,
// times its albedo / pi. The grid's points are filled by gridGather: rays from each point
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

// Indirect radiance arriving at a grid point from direction ray.d: light that has left a
// diffuse-like surface at least once, hitRadiance(si, wi, smp, rays) (direct light there plus
// photon irradiance), followed through mirrors, glass and sharp glossy lobes. What the ray
// sees of emitters and the map is counted only after a non-delta bounce: seen directly it is
// direct light (the pixel adds it), and seen through mirrors and glass alone it is a caustic,
// which the caustic map gives per pixel. *backFace: the first surface was met from behind (the
// point may be inside something), one-sided or not.
template <class Tracer, class HitRadiance>
ENVGI_HD Color gridGather(const SceneView& sc, const Tracer& tracer, Ray ray, Sampler& smp, const ChainParams& cp,
                          const HitRadiance& hitRadiance, bool* backFace, uint64_t* rays) {
  Color beta(1.f), L(0.f);
  bool throughGlossy = false;  // a non-delta bounce so far: emitters and the map now count
  *backFace = false;
  for (int depth = 0; depth < cp.maxDepth; ++depth) {
    Hit h;
    ++*rays;
    if (!tracer.intersect(ray, &h)) {
      if (throughGlossy && sc.hasEnvironment) L += beta * sc.env.eval(ray.d);
      return L;
    }
    SurfaceInteraction si = sc.interaction(ray, h);
    BsdfScratch textured;
    const Bsdf& bsdf = sc.bsdfAt(si, &textured);
    // The geometric side, whatever the material: a two-sided closed surface (the Buddha's) still
    // has an inside, and its back is what a point in there sees. Only a one-sided back is black.
    if (depth == 0 && dot(si.ng, ray.d) > 0.f && !bsdfTransmits(bsdf)) {
      *backFace = true;
      if (!bsdf.twoSided) return Color(0.f);
    }
    if (throughGlossy) L += beta * sc.emitted(si, -ray.d);
    if (isDiffuseLike(bsdf, cp.glossyThreshold)) return L + beta * hitRadiance(si, ray.d, smp, rays);
    BsdfSample bs;
    float uc = smp.get1D();
    Vec2f ub = smp.get2D();
    if (!bsdfSample(bsdf, si.shading.toLocal(-ray.d), uc, ub, &bs)) return L;
    beta *= bs.weight;
    if (isBlack(beta)) return L;
    throughGlossy = throughGlossy || !bs.delta;
    Vec3f wi = si.shading.toWorld(bs.wi);
    ray = Ray{offsetRayOrigin(si.p, si.ng, wi, si.t), wi, INFINITY};
  }
  return L;
}

// Rays [first, first + rays) of grid point i at p: radiance gathered by gridGather, projected
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
    Color L = gridGather(sc, tracer, Ray{p, d, INFINITY}, smp, cp, hitRadiance, &isBack, rayCount);
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
