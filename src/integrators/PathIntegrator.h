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

// Where a bounce's draws lie, in dimensions past the sampler's position as pathShade begins
// (drawBounce's order): with a light sample, the light's pair at 1 (after the light kind's old
// dimension) and the area light's second pair, then the BSDF's 1D draw and its pair; without,
// the BSDF's first. Roulette's draw follows. An executor that draws a round's pairs in lanes
// (RoundLanes) reads the offsets here, the one place they are written.
struct BounceLayout {
  uint32_t light, bsdf;  // the light's pair, the BSDF's pair
};
ENVGI_HD inline BounceLayout bounceLayout(const PathParams& pp) {
  return pp.lightSample ? BounceLayout{1u, 6u} : BounceLayout{1u, 1u};
}

// What an executor works out for a hit before shading it (CPU: the tile wavefront, which walks
// a round's map draws level by level first): the interaction, the light's and the BSDF's 2D
// draws where it drew them in lanes (at bounceLayout's offsets), and work done with them.
// pathShade then takes them instead of redoing them.
struct ShadeAhead {
  SurfaceInteraction si;
  bool lightDrawn = false;  // uL holds the light's pair (the path goes on to next-event estimation)
  Vec2f uL;
  bool bsdfDrawn = false;  // ub holds the BSDF's pair
  Vec2f ub;
  BsdfSampleAhead bs;  // the BSDF's sample for ub, where that was worked out ahead
  BsdfEvalAhead ev;    // the BSDF at the product draw's direction, where that was worked out ahead
  // The map's product draw for uL, where the executor walked it to its end (aheadDraw).
  bool productAhead = false;
  ProductDraw product;
  // For a ray that escaped: where it meets the map, found ahead (RoundLanes::mapUV); pathShade
  // then looks the map up there instead of finding (u, v) again.
  bool escaped = false;
  Vec2f uv;
};

// A bounce's random numbers: the light sample's, the BSDF sample's and roulette's.
struct BounceDraws {
  LightDraws light;
  BsdfDraws bsdf;
  float rr = 0.f;
};
// The one place a bounce's draws are taken from the sampler, in bounceLayout's order; each is
// taken only where the bounce uses it (roulette's from rrDepth on). ahead: pairs drawn in lanes.
ENVGI_HD inline BounceDraws drawBounce(const SceneView& sc, const Bsdf& bsdf, const PathParams& pp, int depth,
                                       Sampler& smp, const ShadeAhead* ahead) {
  BounceDraws u;
  if (pp.lightSample) u.light = drawLight(sc, smp, ahead && ahead->lightDrawn ? &ahead->uL : nullptr);
  if (!pp.bsdfSample) return u;
  u.bsdf = drawBsdf(bsdf, smp, ahead && ahead->bsdfDrawn ? &ahead->ub : nullptr);
  if (depth >= pp.rrDepth) u.rr = smp.get1D();
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

// What a path's ray that escaped sees of the map: radiance Le, whose MIS weight is w (the
// path adds beta * Le * w). uv: where the ray meets the map, found ahead (or none).
struct EscapedLight {
  Color Le;
  float w = 0.f;
  bool seen = false;  // false: the ray adds nothing (no map, a hidden one, or one drawn only)
};
// radiance: the map's radiance at uv, looked up ahead (RoundLanes::mapRadiance), if it was.
ENVGI_HD inline EscapedLight pathEscape(const SceneView& sc, const PathState& st, const PathParams& pp,
                                        const Vec2f* uv, const Color* radiance = nullptr) {
  EscapedLight e;
  if (!(sc.hasEnvironment && !(st.depth == 1 && pp.hideEmitters) && envSeenByBsdfSampling(pp.envStrategy, st.prevDelta)))
    return e;
  // What this ray finds takes no MIS weight where no light sample could have drawn it: after a
  // delta bounce, or without next-event estimation. Nor is the map's light density read then.
  const bool unweighted = st.prevDelta || !pp.lightSample;
  float lightPdf = 0.f;
  e.Le = unweighted ? (radiance ? *radiance : uv ? sc.env.lookupUV(*uv) : sc.env.eval(st.ray.d))
                    : envRadianceAndPdf(sc, pp.envStrategy, st.ray.d, st.prevAxis, &lightPdf, uv);
  e.w = unweighted ? 1.f : powerHeuristic(1.f, st.prevPdf, 1.f, lightPdf);
  e.seen = true;
  return e;
}

// What a camera ray that escaped adds: pathShade's sum for it, begun at pathBegin (beta 1, no
// delta before it), without a PathState (the CPU's camera rounds: RoundLanes). radiance: the
// map's radiance at uv, looked up ahead, if it was.
ENVGI_HD inline Color cameraEscape(const SceneView& sc, const Ray& ray, const PathParams& pp, const Vec2f* uv,
                                   const Color* radiance = nullptr) {
  const PathState st = pathBegin(ray);
  const EscapedLight e = pathEscape(sc, st, pp, uv, radiance);
  Color L = st.L;
  if (e.seen) L += st.beta * e.Le * e.w;
  return L;
}

// One bounce of the path after st->ray has been traced (found: whether it hit, h: where): add
// what it sees to st->L, hand next-event estimation's sample to shadow (ShadowRayNow or an
// executor's batch), sample the BSDF for the next ray. Returns false once the path has ended.
// Apart from pathStep, so that an executor can trace many paths' rays together, then shade them.
// ahead: pathShadeAhead's work for this hit, or for an escaped ray its radiance; or none.
template <class Shadow>
ENVGI_HD bool pathShade(const SceneView& sc, PathState* st, bool found, const Hit& h, Sampler& smp,
                        const PathParams& pp, const Shadow& shadow, const ShadeAhead* ahead = nullptr) {
  const int depth = st->depth;
  const Ray& ray = st->ray;
  if (!found) {
    const EscapedLight e = pathEscape(sc, *st, pp, ahead && ahead->escaped ? &ahead->uv : nullptr);
    if (e.seen) st->L += st->beta * e.Le * e.w;
    return false;
  }
  // As for an escaped ray (pathEscape), an emitter hit takes no MIS weight where no light
  // sample could have drawn it.
  const bool unweighted = st->prevDelta || !pp.lightSample;
  const SurfaceInteraction si = ahead ? ahead->si : sc.interaction(ray, h);
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
  const Bsdf* partner = sc.partnerAt(si, &texturedPartner);
  Vec3f woLocal = si.shading.toLocal(wo);
  Vec3f axis = envSamplingAxis(si, wo, bsdf);

  const BounceDraws u = drawBounce(sc, bsdf, pp, depth, smp, ahead);

  // Next-event estimation, weighted against this bounce's BSDF sample.
  if (pp.lightSample)
    shadow(prepareLd(sc, si, bsdf, woLocal, axis, pp.envStrategy, 1.f, pp.bsdfSample ? 1.f : 0.f, MisHeuristic::Power,
                     u.light, partner, ahead && ahead->productAhead ? &ahead->product : nullptr,
                     ahead ? &ahead->ev : nullptr),
           st);
  if (!pp.bsdfSample) return false;

  BsdfSample bs;
  if (!drawBsdfSample(bsdf, woLocal, u.bsdf, &bs, ahead ? &ahead->bs : nullptr)) return false;
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

// What pathShade will read from the map for a path whose ray escaped and meets the map at uv,
// asked for ahead (CPU only: the tile wavefront prefetches a round's escapes before shading it).
inline void pathPrefetchEscape(const SceneView& sc, const PathState& st, const PathParams& pp, Vec2f uv) {
  if (sc.hasEnvironment && !st.prevDelta && envSeenByBsdfSampling(pp.envStrategy, false))
    sc.env.prefetchEvalWithPdf(pp.envStrategy, uv, st.prevAxis);
}

// pathShade's first steps for a path whose ray hit, done ahead into *ahead (CPU only): its
// interaction and, where it goes on to next-event estimation, its light pair (uL: that pair
// drawn in lanes, if it was; else from a copy of smp). Where that draw is the product's, *draw
// gets the first level of its loads (CosineProductView::aheadLevel0) and it returns true.
inline bool pathShadeAhead(const SceneView& sc, const PathState& st, const Hit& h, const Sampler& smp,
                           const PathParams& pp, ShadeAhead* ahead, ProductDrawAhead* draw,
                           const Vec2f* uL = nullptr) {
  ahead->si = sc.interaction(st.ray, h);
  ahead->productAhead = false;
  ahead->bs.made = false;
  ahead->ev.made = false;
  ahead->lightDrawn = pp.lightSample && !(pp.maxDepth >= 0 && st.depth >= pp.maxDepth);
  if (!ahead->lightDrawn) return false;
  if (uL) {
    ahead->uL = *uL;
  } else {
    Sampler peek = smp;
    ahead->uL = drawLight(sc, peek).uL;
  }
  // The material's own entry, untextured: its type is all that is asked of it here.
  const Bsdf& bsdf = sc.bsdfs[ahead->si.bsdf];
  Vec2f u = ahead->uL;
  const float pe = sc.envSelectProb();
  if (!sc.hasEnvironment || bsdfIsDelta(bsdf) || !(u.x < pe)) return false;
  const Vec3f axis = envSamplingAxis(ahead->si, -st.ray.d, bsdf);
  if (sc.env.strategyFor(pp.envStrategy, axis) != EnvStrategy::Product) return false;
  if (pe < 1.f) u.x = stretchedDraw(u.x, 0.f, pe);
  sc.env.product.aheadLevel0(u, sc.env.toLocalUnnormalized(axis), draw);
  return draw->k >= 0;
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
