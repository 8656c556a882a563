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

// A path between bounces: what pathStep carries from one bounce to the next. Plain data, so a
// GPU thread can hold one, end it, and start another (path regeneration).
struct PathState {
  Ray ray;
  Color L, beta;
  float etaScale;  // product of eta^2 over refractions, for Russian roulette
  float prevPdf;
  bool prevDelta;
  Vec3f prevP, prevAxis;
  int depth;
};

ENVGI_HD inline PathState pathBegin(const Ray& ray) {
  return {ray, Color(0.f), Color(1.f), 1.f, 0.f, true, ray.o, Vec3f(0.f, 0.f, 1.f), 1};
}

// Next-event estimation's shadow ray traced at once, its contribution added to the path
// (pathStep's way; an executor that traces many paths' shadow rays together keeps ld and the
// path's beta instead, and adds beta * resolvedLd(ld, blocked) before the path goes on).
template <class Tracer>
struct ShadowRayNow {
  const Tracer& tracer;
  uint64_t* rayCount;
  ENVGI_HD void operator()(const LightSampleLd& ld, PathState* st) const {
    st->L += st->beta * resolvedLd(ld, shadowRayBlocked(tracer, ld, rayCount));
  }
};

// One bounce of the path after st->ray has been traced (found: whether it hit, h: where): add
// what it sees to st->L, hand next-event estimation's sample to shadow (ShadowRayNow or an
// executor's batch), sample the BSDF for the next ray. Returns false once the path has ended.
// Apart from pathStep, so that an executor can trace many paths' rays together, then shade them.
template <class Shadow>
ENVGI_HD bool pathShade(const SceneView& sc, PathState* st, bool found, const Hit& h, Sampler& smp,
                        const PathParams& pp, const Shadow& shadow) {
  const int depth = st->depth;
  const Ray& ray = st->ray;
  if (!found) {
    if (sc.hasEnvironment && !(depth == 1 && pp.hideEmitters) && envSeenByBsdfSampling(pp.envStrategy, st->prevDelta)) {
      float lightPdf = 0.f;
      Color Le = st->prevDelta ? sc.env.eval(ray.d)
                               : envRadianceAndPdf(sc, pp.envStrategy, ray.d, st->prevAxis, &lightPdf);
      float w = st->prevDelta ? 1.f : powerHeuristic(1.f, st->prevPdf, 1.f, lightPdf);
      st->L += st->beta * Le * w;
    }
    return false;
  }
  SurfaceInteraction si = sc.interaction(ray, h);
  Vec3f wo = -ray.d;
  if (si.light >= 0 && !(depth == 1 && pp.hideEmitters)) {
    Color Le = sc.emitted(si, wo);
    if (!isBlack(Le)) {
      float w = st->prevDelta ? 1.f
                              : powerHeuristic(1.f, st->prevPdf, 1.f, areaLightPdf(sc, si.light, st->prevP, si.p, si.ng));
      st->L += st->beta * Le * w;
    }
  }
  if (pp.maxDepth >= 0 && depth >= pp.maxDepth) return false;
  BsdfScratch textured, texturedPartner;
  const Bsdf& bsdf = sc.bsdfAt(si, &textured);
  // A blend's other material: the two are evaluated as their mix (materials/BsdfMix.h).
  const Bsdf* partner = sc.partnerAt(si, &texturedPartner);
  Vec3f woLocal = si.shading.toLocal(wo);
  Vec3f axis = envSamplingAxis(si, wo, bsdf);

  // Next-event estimation, weighted against this bounce's BSDF sample.
  shadow(prepareLd(sc, si, bsdf, woLocal, axis, pp.envStrategy, 1.f, 1.f, smp, partner), st);

  BsdfSample bs;
  if (!drawBsdfSample(bsdf, woLocal, smp, &bs)) return false;
  if (partner) bsdfMixReweight(*partner, si.partnerWeight, woLocal, &bs);
  Vec3f wi = si.shading.toWorld(bs.wi);
  st->beta *= bs.weight;
  st->etaScale *= bsdfEtaSquared(bsdf, woLocal, bs.wi);
  if (isBlack(st->beta)) return false;
  st->prevPdf = bs.pdf;
  st->prevDelta = bs.delta;
  st->prevP = si.p;
  st->prevAxis = axis;
  st->ray.o = offsetRayOrigin(si.p, si.ng, wi, si.t);
  st->ray.d = wi;
  st->ray.tMax = INFINITY;
  st->depth = depth + 1;
  return depth < pp.rrDepth || russianRoulette(&st->beta, smp.get1D(), kRouletteMaxSurvival, st->etaScale);
}

// What pathShade will read from the map for a path whose ray escaped, asked for ahead (CPU
// only: renderTileByBounce prefetches a round's escapes before shading it).
inline void pathPrefetchEscape(const SceneView& sc, const PathState& st, const PathParams& pp) {
  if (sc.hasEnvironment && !st.prevDelta && envSeenByBsdfSampling(pp.envStrategy, false))
    sc.env.prefetchEvalWithPdf(pp.envStrategy, st.ray.d, st.prevAxis);
}

// One bounce of the path: trace st->ray, then pathShade.
template <class Tracer>
ENVGI_HD bool pathStep(const SceneView& sc, const Tracer& tracer, PathState* st, Sampler& smp, const PathParams& pp,
                       uint64_t* rayCount) {
  Hit h;
  ++*rayCount;
  bool found = tracer.intersect(st->ray, &h);
  return pathShade(sc, st, found, h, smp, pp, ShadowRayNow<Tracer>{tracer, rayCount});
}

template <class Tracer>
ENVGI_HD Color pathTrace(const SceneView& sc, const Tracer& tracer, Ray ray, Sampler& smp, const PathParams& pp,
                         uint64_t* rayCount) {
  PathState st = pathBegin(ray);
  while (pathStep(sc, tracer, &st, smp, pp, rayCount)) {
  }
  return st.L;
}

}  // namespace envgi
