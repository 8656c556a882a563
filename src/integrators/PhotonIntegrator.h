// Jensen's two-pass photon mapping, second pass (the paper's Eq. 7-12): at the first
// diffuse-like surface a camera path reaches (after mirrors, glass and sharp glossy lobes),
// direct light by light sampling with MIS, caustics read from the caustic map, and indirect
// light by a final gather whose rays read the global map (or the global map directly when
// gather_samples is 0). CPU only: the maps live in kd-trees.
#pragma once

#include "integrators/DirectIntegrator.h"
#include "photon/PhotonMap.h"
#include "sampling/Roulette.h"

namespace envgi {

struct PhotonRenderParams {
  PhotonLookup global, caustic;
  int gatherSamples = 8;
  int maxDepth = kSpecularChainDepth;  // specular/glossy chain length from the camera
  int rrDepth = kRouletteDepth;
  float glossyThreshold = 0.3f;  // rough lobes sharper than this are followed, not estimated
  bool hideEmitters = false;
  EnvStrategy strategy = EnvStrategy::Alias;
};

// True where the photon estimate stands in for the rest of the path.
ENVGI_INLINE bool isDiffuseLike(const Bsdf& b, float glossyThreshold) {
  switch (b.type) {
    case BsdfType::Diffuse:
    case BsdfType::Plastic:
    case BsdfType::RoughPlastic: return true;
    // Rough glass is followed like glass: its light comes mostly through it, which irradiance
    // on its surface cannot stand for.
    case BsdfType::RoughConductor: return b.alpha >= glossyThreshold;
    case BsdfType::Conductor:
    case BsdfType::Dielectric:
    case BsdfType::ThinDielectric:
    case BsdfType::RoughDielectric: return false;
  }
  return false;
}

// Lambertian-equivalent albedo of a diffuse-like BSDF, for the precomputed irradiance that
// final-gather rays read (an approximation where the BSDF is not Lambertian).
ENVGI_INLINE Color diffuseAlbedo(const Bsdf& b) {
  switch (b.type) {
    case BsdfType::Diffuse: return b.reflectance;
    case BsdfType::Plastic:
    case BsdfType::RoughPlastic: {
      // The base's albedo towards the normal under uniform light: light enters through the coat
      // with 1 - Fdr (the coat's hemispherical Fresnel from outside) and leaves with 1 - F(0).
      float tOut = 1.f - fresnelDielectric(1.f, b.ior), tIn = 1.f - b.fdrExt;
      return b.reflectance * (tOut * tIn / ((1.f - b.fdrInt) * b.ior * b.ior));
    }
    case BsdfType::RoughConductor:
      return b.specularReflectance * (b.perfectMirror ? Color(1.f) : fresnelConductor(1.f, b.eta, b.k));
    case BsdfType::Conductor:
    case BsdfType::Dielectric:
    case BsdfType::ThinDielectric:
    case BsdfType::RoughDielectric: return Color(0.f);
  }
  return Color(0.f);
}

template <class Tracer>
Color photonTrace(const SceneView& sc, const Tracer& tracer, Ray ray, Sampler& smp, const PhotonMap& global,
                  const PhotonMap& caustic, const PhotonRenderParams& pp, uint64_t* rays) {
  Color L(0.f), beta(1.f);
  bool countEmission = !pp.hideEmitters;  // camera rays and specular bounces see emitters
  for (int depth = 0; depth < pp.maxDepth; ++depth) {
    Hit h;
    ++*rays;
    if (!tracer.intersect(ray, &h)) {
      if (countEmission && sc.hasEnvironment) L += beta * sc.env.eval(ray.d);
      break;
    }
    SurfaceInteraction si = sc.interaction(ray, h);
    Vec3f wo = -ray.d;
    if (countEmission) L += beta * sc.emitted(si, wo);
    const Bsdf& bsdf = sc.bsdfs[si.bsdf];
    // Smooth plastic's coat is a mirror: follow it with its sampling probability (what it
    // reflects may be lit, not emitting), and estimate the base here otherwise.
    float pDelta = bsdfDeltaProb(bsdf, si.shading.toLocal(wo));
    float uLobe = pDelta > 0.f && pDelta < 1.f ? smp.get1D() : 1.f;
    if (pDelta < 1.f && uLobe >= pDelta) {
      beta = beta / (1.f - pDelta);
      L += beta * directLighting(sc, tracer, si, wo, smp, pp.strategy, 1, 1, rays, true);
      if (isDiffuseLike(bsdf, pp.glossyThreshold)) {
        L += beta * caustic.estimate(sc, si, wo, pp.caustic);
        if (pp.gatherSamples <= 0) {
          L += beta * global.estimate(sc, si, wo, pp.global);
          break;
        }
        // Final gather: indirect light from the global map one bounce away. Where a gather
        // ray meets a specular surface its light is left out (caustic paths are in the
        // caustic map; light bouncing diffusely and then through glass onto here is lost).
        Vec3f woLocal = si.shading.toLocal(wo);
        Color gather(0.f);
        for (int g = 0; g < pp.gatherSamples; ++g) {
          BsdfSample bs;
          float uc = smp.get1D();
          Vec2f ub = smp.get2D();
          if (!bsdfSample(bsdf, woLocal, uc, ub, &bs) || bs.delta) continue;
          Vec3f wi = si.shading.toWorld(bs.wi);
          Ray gr{offsetRayOrigin(si.p, si.ng, wi, si.t), wi, INFINITY};
          Hit gh;
          ++*rays;
          if (!tracer.intersect(gr, &gh)) continue;  // the environment is direct light, counted above
          SurfaceInteraction gs = sc.interaction(gr, gh);
          const Bsdf& gb = sc.bsdfs[gs.bsdf];
          if (bsdfIsDelta(gb)) continue;
          Vec3f ny = faceForward(gs.ng, -wi);
          Color Ly = directLighting(sc, tracer, gs, -wi, smp, pp.strategy, 1, 0, rays) +
                     diffuseAlbedo(gb) * kInvPi * (global.irradiance(gs.p, ny) + caustic.irradiance(gs.p, ny));
          gather += bs.weight * Ly;
        }
        L += beta * gather / float(pp.gatherSamples);
        break;
      }
    }
    // Mirrors, glass and sharp glossy lobes: follow the path.
    BsdfSample bs;
    float uc = pDelta > 0.f && pDelta < 1.f ? uLobe : smp.get1D();  // < pDelta: the coat
    Vec2f ub = smp.get2D();
    if (!bsdfSample(bsdf, si.shading.toLocal(wo), uc, ub, &bs)) break;
    if (pDelta > 0.f && pDelta < 1.f && !bs.delta) break;
    beta *= bs.weight;
    if (isBlack(beta)) break;
    countEmission = bs.delta;  // after a glossy bounce, directLighting counted the emitters
    Vec3f wi = si.shading.toWorld(bs.wi);
    ray = Ray{offsetRayOrigin(si.p, si.ng, wi, si.t), wi, INFINITY};
    if (depth + 1 >= pp.rrDepth && !russianRoulette(&beta, smp.get1D(), kRouletteMaxSurvival)) break;
  }
  return L;
}

}  // namespace envgi
