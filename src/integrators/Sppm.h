// Stochastic progressive photon mapping (Hachisuka and Jensen 2009). Each pass traces one
// camera path per pixel to its first non-specular surface (a visible point, with direct light
// by MIS there), shoots photons, and gathers them at visible points through a hashed grid;
// per-pixel radii shrink with alpha. This is the per-path, host/device part; the driver that
// runs its passes is render/SppmExecutor.
#pragma once

#include "integrators/DirectIntegrator.h"
#include "photon/HashGrid.h"
#include "photon/PhotonTracing.h"
#include "scene/IntegratorSettings.h"
#include "scene/SceneView.h"

namespace envgi {

struct VisiblePoint {
  Vec3f p;
  Vec3f wo;
  Frame shading;
  Color beta;
  int bsdf = 0;
  bool valid = false;
};

// Camera path through specular bounces to the first non-delta surface; adds emission seen
// along the way and direct light at the visible point to *Ld.
template <class Tracer>
ENVGI_HD VisiblePoint sppmCameraPath(const SceneView& sc, const Tracer& tracer, Ray ray, Sampler& smp, int maxDepth,
                                     EnvStrategy strategy, Color* Ld, uint64_t* rays) {
  VisiblePoint vp;
  Color beta(1.f);
  for (int depth = 0; depth < maxDepth; ++depth) {
    Hit h;
    ++*rays;
    if (!tracer.intersect(ray, &h)) {
      if (sc.hasEnvironment) *Ld += beta * sc.env.eval(ray.d);
      return vp;
    }
    SurfaceInteraction si = sc.interaction(ray, h);
    Vec3f wo = -ray.d;
    *Ld += beta * sc.emitted(si, wo);
    const Bsdf& bsdf = sc.bsdfs[si.bsdf];
    // Smooth plastic's coat is a mirror: follow it with its sampling probability (what it
    // reflects may be lit, not emitting), and make the visible point on the base otherwise.
    float pDelta = bsdfDeltaProb(bsdf, si.shading.toLocal(wo));
    float uLobe = smp.get1D();
    if (pDelta < 1.f && uLobe >= pDelta) {
      beta = beta / (1.f - pDelta);
      *Ld += beta * directLighting(sc, tracer, si, wo, smp, strategy, 1, 1, rays, true);
      vp.p = si.p;
      vp.wo = wo;
      vp.shading = si.shading;
      vp.beta = beta;
      vp.bsdf = si.bsdf;
      vp.valid = true;
      return vp;
    }
    BsdfSample bs;
    float uc = pDelta < 1.f ? uLobe : smp.get1D();  // < pDelta: bsdfSample picks the coat
    Vec2f ub = smp.get2D();
    if (!bsdfSample(bsdf, si.shading.toLocal(wo), uc, ub, &bs) || !bs.delta) return vp;
    beta *= bs.weight;
    Vec3f wi = si.shading.toWorld(bs.wi);
    ray = Ray{offsetRayOrigin(si.p, si.ng, wi, si.t), wi, INFINITY};
  }
  return vp;
}

// A photon's contribution f(wo, wi) beta_vp Phi at one visible point within its radius.
ENVGI_INLINE Color sppmContribution(const SceneView& sc, const VisiblePoint& vp, Vec3f wi, Color power) {
  const Bsdf& b = sc.bsdfs[vp.bsdf];
  Vec3f wiLocal = vp.shading.toLocal(wi);
  float c = std::fabs(wiLocal.z);
  if (c <= 0.f) return Color(0.f);
  return vp.beta * bsdfEval(b, vp.shading.toLocal(vp.wo), wiLocal) * power / c;
}

struct SppmParams {
  size_t photonsPerPass = 100000;
  float initialRadius = 0.f;  // 0: 1% of the scene's bounding-sphere radius
  float alpha = 2.f / 3.f;
  int maxDepth = kSpecularChainDepth;
  uint32_t seed = 0;
  EnvStrategy strategy = EnvStrategy::Alias;
};

}  // namespace envgi
