// Camera paths through mirrors, glass and sharp glossy lobes to the first diffuse-like surface,
// where an estimator stands in for the rest of the path: the photon maps (photon), the grid of
// illumination coefficients (grid). Emission is counted along the chain; the estimator adds
// direct light and its own indirect term. Host/device; the estimator is a template parameter.
#pragma once

#include "integrators/DirectIntegrator.h"
#include "materials/Fresnel.h"
#include "sampling/Roulette.h"
#include "scene/IntegratorSettings.h"

namespace envgi {

struct ChainParams {
  int maxDepth = kSpecularChainDepth;  // chain length from the camera
  int rrDepth = kRouletteDepth;
  float glossyThreshold = 0.3f;        // rough lobes sharper than this are followed, not estimated
  bool hideEmitters = false;
  EnvStrategy strategy = EnvStrategy::Alias;
};

// True where an estimate stands in for the rest of the path.
ENVGI_INLINE bool isDiffuseLike(const Bsdf& b, float glossyThreshold) {
  switch (b.type) {
    case BsdfType::Diffuse:
    case BsdfType::Plastic:
    case BsdfType::RoughPlastic: return true;
    // Rough glass is followed like glass: its light comes mostly through it, which irradiance
    // on its surface cannot stand for.
    // An anisotropic one must be rough both ways: sharp along one axis, it still mirrors.
    case BsdfType::RoughConductor: return fminf(b.alpha, microfacet(b).alphaY) >= glossyThreshold;
    // Principled: where most of it is the diffuse base, or its specular lobe is rough enough.
    case BsdfType::Principled: {
      const PrincipledParams& p = b.principled;
      if (p.specTrans > 0.f) return false;  // glass, as rough glass
      MicrofacetDistribution d = principled::specularLobe(p);
      return p.metallic < 0.5f || fminf(d.alphaX, d.alphaY) >= glossyThreshold;
    }
    case BsdfType::Conductor:
    case BsdfType::Dielectric:
    case BsdfType::ThinDielectric:
    case BsdfType::RoughDielectric: return false;
  }
  return false;
}

// Lambertian-equivalent albedo of a diffuse-like BSDF, for estimates that know irradiance only
// (an approximation where the BSDF is not Lambertian).
ENVGI_INLINE Color diffuseAlbedo(const Bsdf& b) {
  switch (b.type) {
    case BsdfType::Diffuse: return b.reflectance;
    case BsdfType::Plastic:
    case BsdfType::RoughPlastic: {
      // The base's albedo towards the normal under uniform light: light enters through the coat
      // with 1 - Fdr (the coat's hemispherical Fresnel from outside) and leaves with 1 - F(0);
      // through a rough coat, with its tables' hemispherical and normal transmittances.
      if (b.type == BsdfType::RoughPlastic && b.coatNodes > 0) {
        CoatNode n = detail::roughCoat(b);
        return detail::plasticBase(b, coatInternalReflectance(n), coatTransmittance(n, 1.f) * coatDiffuseTransmittance(n));
      }
      float tOut = 1.f - fresnelDielectric(1.f, b.ior), tIn = 1.f - b.fdrExt;
      return detail::plasticBase(b, b.fdrInt, tOut * tIn);
    }
    case BsdfType::RoughConductor:
      return b.specularReflectance * (b.perfectMirror ? Color(1.f) : fresnelConductor(1.f, b.eta, b.k));
    case BsdfType::Principled:  // the base and the metal's colour, each by its weight
      return b.reflectance * (principled::baseWeight(b.principled) + b.principled.metallic);
    case BsdfType::Conductor:
    case BsdfType::Dielectric:
    case BsdfType::ThinDielectric:
    case BsdfType::RoughDielectric: return Color(0.f);
  }
  return Color(0.f);
}

// estimate(si, wo, smp, rays) -> Color: the indirect light leaving a diffuse-like surface
// towards wo (direct light is added here). Returns the path's radiance.
template <class Tracer, class Estimate>
ENVGI_HD Color traceSpecularChain(const SceneView& sc, const Tracer& tracer, Ray ray, Sampler& smp,
                                  const ChainParams& cp, const Estimate& estimate, uint64_t* rays) {
  Color L(0.f), beta(1.f);
  float etaScale = 1.f;  // product of eta^2 over refractions, for Russian roulette
  bool countEmission = !cp.hideEmitters;  // camera rays and specular bounces see emitters
  for (int depth = 0; depth < cp.maxDepth; ++depth) {
    Hit h;
    ++*rays;
    if (!tracer.intersect(ray, &h)) {
      if (countEmission && sc.hasEnvironment) L += beta * sc.env.eval(ray.d);
      break;
    }
    SurfaceInteraction si = sc.interaction(ray, h);
    Vec3f wo = -ray.d;
    if (countEmission) L += beta * sc.emitted(si, wo);
    BsdfScratch textured;
    const Bsdf& bsdf = sc.bsdfAt(si, &textured);
    // Smooth plastic's coat is a mirror: follow it with its sampling probability (what it
    // reflects may be lit, not emitting), and estimate the base here otherwise.
    float pDelta = bsdfDeltaProb(bsdf, si.shading.toLocal(wo));
    float uLobe = pDelta > 0.f && pDelta < 1.f ? smp.get1D() : 1.f;
    if (pDelta < 1.f && uLobe >= pDelta) {
      beta = beta / (1.f - pDelta);
      L += beta * directLighting(sc, tracer, si, wo, smp, cp.strategy, 1, 1, rays, true);
      if (isDiffuseLike(bsdf, cp.glossyThreshold)) {
        L += beta * estimate(si, wo, smp, rays);
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
    etaScale *= bsdfEtaSquared(bsdf, si.shading.toLocal(wo), bs.wi);
    countEmission = bs.delta;  // after a glossy bounce, directLighting counted the emitters
    Vec3f wi = si.shading.toWorld(bs.wi);
    ray = Ray{offsetRayOrigin(si.p, si.ng, wi, si.t), wi, INFINITY};
    if (depth + 1 >= cp.rrDepth && !russianRoulette(&beta, smp.get1D(), kRouletteMaxSurvival, etaScale)) break;
  }
  return L;
}

}  // namespace envgi
