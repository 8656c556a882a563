// What a gather ray brings back: followed through mirrors, glass and sharp glossy lobes to the
// diffuse-like surface it lands on, direct light there by one light sample, plus the photon
// maps' precomputed irradiance (indirect and caustic) times the albedo / pi. The photon
// integrator's final gather and the grid's fill share it; host and device.
#pragma once

#include "integrators/DirectIntegrator.h"
#include "integrators/SpecularChain.h"
#include "photon/IrradianceCache.h"

namespace envgi {

// Light leaving gs towards -wi.
template <class Tracer>
ENVGI_HD Color gatherHitRadiance(const SceneView& sc, const Tracer& tracer, const SurfaceInteraction& gs, Vec3f wi,
                                 Sampler& smp, EnvStrategy strategy, const IrradianceCacheView& global,
                                 const IrradianceCacheView& caustic, uint64_t* rays) {
  Vec3f ny = faceForward(gs.ng, -wi);
  return directLighting(sc, tracer, gs, -wi, smp, strategy, 1, 0, rays) +
         diffuseAlbedo(sc.bsdfAt(gs.bsdf, gs.uv)) * kInvPi * (global.irradiance(gs.p, ny) + caustic.irradiance(gs.p, ny));
}

// Indirect radiance arriving at ray.o (a grid point, or a surface's final gather) from ray.d:
// light that has left a diffuse-like surface at least once, hitRadiance(si, wi, smp, rays)
// (direct light there plus photon irradiance), followed through mirrors, glass and sharp
// glossy lobes. What the ray sees of emitters and the map is counted only after a non-delta
// bounce: seen directly it is direct light (the pixel adds it), and seen through mirrors and
// glass alone it is a caustic, which the caustic map gives per pixel. *backFace: the first surface was met from behind (the
// point may be inside something), one-sided or not.
template <class Tracer, class HitRadiance>
ENVGI_HD Color gatherRay(const SceneView& sc, const Tracer& tracer, Ray ray, Sampler& smp, const ChainParams& cp,
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

}  // namespace envgi
