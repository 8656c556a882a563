// Jensen's two-pass photon mapping, second pass (the paper's Eq. 7-12): at the first
// diffuse-like surface a camera path reaches (after mirrors, glass and sharp glossy lobes),
// direct light by light sampling with MIS, caustics read from the caustic map, and indirect
// light by a final gather whose rays read the global map (or the global map directly when
// gather_samples is 0). CPU only: the maps live in kd-trees.
#pragma once

#include "integrators/GatherHit.h"
#include "integrators/SpecularChain.h"
#include "photon/PhotonMap.h"

namespace envgi {

struct PhotonRenderParams {
  ChainParams chain;
  PhotonLookup global, caustic;
  int gatherSamples = 8;
};

template <class Tracer>
Color photonTrace(const SceneView& sc, const Tracer& tracer, const Ray& ray, Sampler& smp, const PhotonMap& global,
                  const PhotonMap& caustic, const PhotonRenderParams& pp, uint64_t* rays) {
  auto estimate = [&](const SurfaceInteraction& si, Vec3f wo, Sampler& s, uint64_t* r) {
    Color L = caustic.estimate(sc, si, wo, pp.caustic);
    if (pp.gatherSamples <= 0) return L + global.estimate(sc, si, wo, pp.global);
    // Final gather: indirect light from the global map one bounce away, followed through
    // mirrors and glass (light -> diffuse -> mirror -> here is in no map: the caustic map holds
    // only light that met nothing diffuse).
    BsdfScratch textured;
    const Bsdf& bsdf = sc.bsdfAt(si, &textured);
    Vec3f woLocal = si.shading.toLocal(wo);
    auto hitRadiance = [&](const SurfaceInteraction& gs, Vec3f wi, Sampler& gsmp, uint64_t* gr) {
      return gatherHitRadiance(sc, tracer, gs, wi, gsmp, pp.chain.strategy, global.irradianceCache().view(),
                               caustic.irradianceCache().view(), gr);
    };
    Color gather(0.f);
    for (int g = 0; g < pp.gatherSamples; ++g) {
      BsdfSample bs;
      float uc = s.get1D();
      Vec2f ub = s.get2D();
      if (!bsdfSample(bsdf, woLocal, uc, ub, &bs) || bs.delta) continue;
      Vec3f wi = si.shading.toWorld(bs.wi);
      bool back = false;
      gather += bs.weight * gatherRay(sc, tracer, Ray{offsetRayOrigin(si.p, si.ng, wi, si.t), wi, INFINITY}, s,
                                      pp.chain, hitRadiance, &back, r);
    }
    return L + gather / float(pp.gatherSamples);
  };
  return traceSpecularChain(sc, tracer, ray, smp, pp.chain, estimate, rays);
}

}  // namespace envgi
