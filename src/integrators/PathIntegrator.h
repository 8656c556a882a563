// Unidirectional path tracing with next-event estimation of the environment map and the
// area lights, MIS (power heuristic) against BSDF sampling, and Russian roulette. Written
// once for any tracer with intersect() and occluded(): Embree or envgi's BVH on the CPU, the
// BVH on the GPU.
#pragma once

#include "integrators/NextEvent.h"
#include "sampling/Roulette.h"
#include "scene/IntegratorSettings.h"

namespace envgi {

// Made from PathSettings (scene/IntegratorSettings.h), whose comments say what each means.
struct PathParams {
  int maxDepth = -1;
  int rrDepth = kRouletteDepth;
  bool hideEmitters = false;
  EnvStrategy envStrategy = EnvStrategy::Product;
};

template <class Tracer>
ENVGI_HD Color pathTrace(const SceneView& sc, const Tracer& tracer, Ray ray, Sampler& smp, const PathParams& pp,
                         uint64_t* rayCount) {
  Color L(0.f), beta(1.f);
  float etaScale = 1.f;  // product of eta^2 over refractions, for Russian roulette
  float prevPdf = 0.f;
  bool prevDelta = true;
  Vec3f prevP = ray.o, prevAxis(0.f, 0.f, 1.f);
  for (int depth = 1;; ++depth) {
    Hit h;
    ++*rayCount;
    if (!tracer.intersect(ray, &h)) {
      if (sc.hasEnvironment && !(depth == 1 && pp.hideEmitters) && envSeenByBsdfSampling(pp.envStrategy, prevDelta)) {
        float lightPdf = 0.f;
        Color Le = prevDelta ? sc.env.eval(ray.d) : envRadianceAndPdf(sc, pp.envStrategy, ray.d, prevAxis, &lightPdf);
        float w = prevDelta ? 1.f : powerHeuristic(1.f, prevPdf, 1.f, lightPdf);
        L += beta * Le * w;
      }
      break;
    }
    SurfaceInteraction si = sc.interaction(ray, h);
    Vec3f wo = -ray.d;
    if (si.light >= 0 && !(depth == 1 && pp.hideEmitters)) {
      Color Le = sc.emitted(si, wo);
      if (!isBlack(Le)) {
        float w = prevDelta ? 1.f : powerHeuristic(1.f, prevPdf, 1.f, areaLightPdf(sc, si.light, prevP, si.p, si.ng));
        L += beta * Le * w;
      }
    }
    if (pp.maxDepth >= 0 && depth >= pp.maxDepth) break;
    const Bsdf& bsdf = sc.bsdfs[si.bsdf];
    Vec3f woLocal = si.shading.toLocal(wo);
    Vec3f axis = envSamplingAxis(si, wo, bsdf);

    // Next-event estimation, weighted against this bounce's BSDF sample.
    L += beta * sampleLd(sc, tracer, si, bsdf, woLocal, axis, pp.envStrategy, 1.f, 1.f, smp, rayCount);

    BsdfSample bs;
    float uc = smp.get1D();
    Vec2f ub = smp.get2D();
    if (!bsdfSample(bsdf, woLocal, uc, ub, &bs)) break;
    Vec3f wi = si.shading.toWorld(bs.wi);
    beta *= bs.weight;
    etaScale *= bsdfEtaSquared(bsdf, woLocal, bs.wi);
    if (isBlack(beta)) break;
    prevPdf = bs.pdf;
    prevDelta = bs.delta;
    prevP = si.p;
    prevAxis = axis;
    ray.o = offsetRayOrigin(si.p, si.ng, wi, si.t);
    ray.d = wi;
    ray.tMax = INFINITY;

    if (depth >= pp.rrDepth && !russianRoulette(&beta, smp.get1D(), kRouletteMaxSurvival, etaScale)) break;
  }
  return L;
}

}  // namespace envgi
