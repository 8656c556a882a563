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
  // direct's sample counts as a path (directAsPath): without a light sample no next-event
  // draw is made and what the BSDF sample finds takes weight 1; without a BSDF sample the path
  // ends after next-event estimation, whose weight is then 1. path itself takes both.
  bool lightSample = true, bsdfSample = true;
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

// Where a bounce's draws lie, in dimensions past the sampler's position as pathShade begins:
// with a light sample, the light's draws (LightDrawLayout), then the BSDF's (BsdfDrawLayout);
// without, the BSDF's first. Roulette's draw follows. drawBounce draws at these offsets, and so
// does any batch of the same draws.
struct BounceLayout {
  uint32_t light, bsdf, roulette;  // the light's pair, the BSDF's pair, roulette's draw
};
ENVGI_HD inline BounceLayout bounceLayout(const PathParams& pp) {
  const uint32_t bsdfDraws = pp.lightSample ? LightDrawLayout::size : 0u;
  return {LightDrawLayout::pair, bsdfDraws + BsdfDrawLayout::pair, bsdfDraws + BsdfDrawLayout::size};
}

// A bounce's random numbers: the light sample's (the light's kind is picked by uL.x), the BSDF
// sample's (its lobe and its pair) and roulette's.
struct BounceDraws {
  LightDraws light;
  BsdfDraws bsdf;
  float rr = 0.f;
};
// The one place a bounce's draws are taken from the sampler, at bounceLayout's offsets; each is
// taken only where the bounce uses it (roulette's from rrDepth on).
template <class Parts>
ENVGI_HD inline BounceDraws drawBounce(const SceneView& sc, const Bsdf& bsdf, const PathParams& pp, int depth,
                                       Sampler& smp, const Parts& parts) {
  const uint32_t base = smp.dim;
  const BounceLayout at = bounceLayout(pp);
  BounceDraws u;
  if (pp.lightSample) u.light = drawLight(sc, smp, parts);
  if (!pp.bsdfSample) return u;
  smp.skipTo(base + at.bsdf - BsdfDrawLayout::pair);
  u.bsdf = drawBsdf(bsdf, smp, parts);
  if (depth < pp.rrDepth) return u;
  smp.skipTo(base + at.roulette);
  u.rr = smp.get1D();
  return u;
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

// Whether a path's ray that escapes sees the map: not where there is none, nor a hidden one
// straight from the camera, nor the collapsed map past a non-delta bounce (only a light sample
// finds its points).
ENVGI_HD inline bool pathSeesMap(const SceneView& sc, const PathState& st, const PathParams& pp) {
  return sc.hasEnvironment && !(st.depth == 1 && pp.hideEmitters) && envSeenByBsdfSampling(pp.envStrategy, st.prevDelta);
}

// A path's ray that escaped: what it sees of the map, MIS-weighted, added to st->L. What it finds
// takes no weight where no light sample could have drawn it: after a delta bounce, or without
// next-event estimation; nor is the map's light density read then.
template <class Parts>
ENVGI_HD inline void pathAddEscape(const SceneView& sc, PathState* st, const PathParams& pp, const Parts& parts) {
  if (!pathSeesMap(sc, *st, pp)) return;
  const Vec2f uv = parts.mapUV(st->ray);
  const Color Le = parts.mapRadiance(uv);
  if (st->prevDelta || !pp.lightSample) {
    st->L += st->beta * Le * 1.f;
    return;
  }
  const float lightPdf = envLightPdfAt(sc, pp.envStrategy, st->ray.d, uv, st->prevAxis);
  st->L += st->beta * Le * powerHeuristic(1.f, st->prevPdf, 1.f, lightPdf);
}

// One bounce of the path after st->ray has been traced (found: whether it hit, h: where): add
// what it sees to st->L, hand next-event estimation's sample to shadow (ShadowRayNow or an
// executor's batch), sample the BSDF for the next ray. Returns false once the path has ended.
// Apart from pathStep, so that an executor can trace many paths' rays together, then shade them.
// Its parts come from parts (BounceParts.h).
template <class Shadow, class Parts>
ENVGI_HD bool pathShade(const SceneView& sc, PathState* st, bool found, const Hit& h, Sampler& smp,
                        const PathParams& pp, const Shadow& shadow, const Parts& parts) {
  const int depth = st->depth;
  const Ray& ray = st->ray;
  if (!found) {
    pathAddEscape(sc, st, pp, parts);
    return false;
  }
  // As for an escaped ray (pathAddEscape), an emitter hit takes no MIS weight where no light
  // sample could have drawn it.
  const bool unweighted = st->prevDelta || !pp.lightSample;
  const SurfaceInteraction si = parts.interaction(ray, h);
  Vec3f wo = -ray.d;
  if (si.light >= 0 && !(depth == 1 && pp.hideEmitters)) {
    Color Le = sc.emitted(si, wo);
    if (!isBlack(Le)) {
      float w = unweighted ? 1.f
                           : powerHeuristic(1.f, st->prevPdf, 1.f, areaLightPdf(sc, si.light, st->prevP, si.p, si.ng));
      st->L += st->beta * Le * w;
    }
  }
  if (pp.maxDepth >= 0 && depth >= pp.maxDepth) return false;
  BsdfScratch textured, texturedPartner;
  const Bsdf& bsdf = sc.bsdfAt(si, &textured);
  // A blend's other material: the two are evaluated as their mix (materials/BsdfMix.h).
  const Bsdf* partner = parts.partner(si, &texturedPartner);
  Vec3f woLocal = si.shading.toLocal(wo);
  Vec3f axis = envSamplingAxis(si, wo, bsdf);

  const BounceDraws u = drawBounce(sc, bsdf, pp, depth, smp, parts);

  // Next-event estimation, weighted against this bounce's BSDF sample.
  if (pp.lightSample)
    shadow(prepareLd(parts, si, bsdf, woLocal, axis, pp.envStrategy, 1.f, pp.bsdfSample ? 1.f : 0.f,
                     MisHeuristic::Power, u.light, partner),
           st);
  if (!pp.bsdfSample) return false;

  BsdfSample bs;
  if (!parts.bsdfSample(bsdf, woLocal, u.bsdf.uc, u.bsdf.ub, &bs)) return false;
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
  return depth < pp.rrDepth || russianRoulette(&st->beta, u.rr, kRouletteMaxSurvival, st->etaScale);
}
template <class Shadow>
ENVGI_HD bool pathShade(const SceneView& sc, PathState* st, bool found, const Hit& h, Sampler& smp,
                        const PathParams& pp, const Shadow& shadow) {
  return pathShade(sc, st, found, h, smp, pp, shadow, SampledParts{sc});
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
