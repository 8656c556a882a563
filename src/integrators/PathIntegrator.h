// Unidirectional path tracing with next-event estimation of the environment map and the
// area lights, MIS (power heuristic) against BSDF sampling, and Russian roulette. Written
// once for any tracer with intersect() and occluded(): Embree on the CPU, a BVH on the GPU.
#pragma once

#include "lights/LightSampling.h"
#include "sampling/Mis.h"
#include "sampling/Sampler.h"

namespace envgi {

struct PathParams {
  int maxDepth = -1;  // Mitsuba's meaning: 1 = emitters seen directly, 2 = direct lighting, -1 = unbounded
  int rrDepth = 5;
  bool hideEmitters = false;
  EnvStrategy envStrategy = EnvStrategy::Importance;
};

template <class Tracer>
ENVGI_HD Color pathTrace(const SceneView& sc, const Tracer& tracer, Ray ray, Sampler& smp, const PathParams& pp,
                         uint64_t* rayCount) {
  Color L(0.f), beta(1.f);
  float prevPdf = 0.f;
  bool prevDelta = true;
  Vec3f prevP = ray.o, prevAxis(0.f, 0.f, 1.f);
  for (int depth = 1;; ++depth) {
    Hit h;
    ++*rayCount;
    if (!tracer.intersect(ray, &h)) {
      if (sc.hasEnvironment && !(depth == 1 && pp.hideEmitters) && envSeenByBsdfSampling(pp.envStrategy, prevDelta)) {
        Color Le = sc.env.eval(ray.d);
        float w = prevDelta ? 1.f : powerHeuristic(1.f, prevPdf, 1.f, envLightPdf(sc, pp.envStrategy, ray.d, prevAxis));
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
    Vec3f axis = cosineAxis(si, wo);

    // Next-event estimation; the sample dimensions are drawn whatever happens, so sequences
    // stay aligned across pixels.
    float uSel = smp.get1D();
    Vec2f uL = smp.get2D(), uL2 = smp.get2D();
    LightSample ls;
    if (!bsdfIsDelta(bsdf) && sampleLight(sc, si, axis, pp.envStrategy, uSel, uL, uL2, &ls)) {
      Vec3f wiLocal = si.shading.toLocal(ls.dir);
      Color f = bsdfEval(bsdf, woLocal, wiLocal);
      if (!isBlack(f) && !isBlack(ls.radiance)) {
        Vec3f o = offsetRayOrigin(si.p, si.ng, ls.dir, si.t);
        float tMax = ls.environment ? INFINITY : ls.dist * (1.f - 1e-4f) - length(o - si.p);
        ++*rayCount;
        if (!tracer.occluded(o, ls.dir, tMax)) {
          float w = ls.delta ? 1.f : powerHeuristic(1.f, ls.pdf, 1.f, bsdfPdf(bsdf, woLocal, wiLocal));
          L += beta * f * ls.radiance * (w / ls.pdf);
        }
      }
    }

    BsdfSample bs;
    float uc = smp.get1D();
    Vec2f ub = smp.get2D();
    if (!bsdfSample(bsdf, woLocal, uc, ub, &bs)) break;
    Vec3f wi = si.shading.toWorld(bs.wi);
    beta *= bs.weight;
    if (isBlack(beta)) break;
    prevPdf = bs.pdf;
    prevDelta = bs.delta;
    prevP = si.p;
    prevAxis = axis;
    ray.o = offsetRayOrigin(si.p, si.ng, wi, si.t);
    ray.d = wi;
    ray.tMax = INFINITY;

    if (depth >= pp.rrDepth) {
      float q = fminf(maxComponent(beta), 0.95f);
      if (smp.get1D() >= q) break;
      beta = beta / q;
    }
  }
  return L;
}

}  // namespace envgi
