// Direct illumination with a chosen environment strategy: emitterSamples light samples and
// bsdfSamples BSDF samples per shading point, combined with the power heuristic weighted by
// the sample counts (Mitsuba's `direct`). With one of the two counts at zero it is the pure
// estimator of the other, so the paper's strategies can be compared on the same image.
#pragma once

#include "integrators/NextEvent.h"

namespace envgi {

struct DirectParams {
  int emitterSamples = 1;
  int bsdfSamples = 1;
  bool hideEmitters = false;
  EnvStrategy envStrategy = EnvStrategy::Importance;
  MisHeuristic heuristic = MisHeuristic::Power;
};

// Direct light reflected at si towards wo (its own emission excluded): nE light samples and
// nB BSDF samples, power heuristic weighted by the counts. Also used by the photon mappers,
// which follow delta lobes themselves and so leave out BSDF samples of them (skipDelta).
// mixBlend: a blend's two materials evaluated as their mix (materials/BsdfMix.h), which only a
// caller that estimates direct light at every hit may ask for; the photon mappers' specular
// chains do so only where the chosen material is not a delta, so they keep the choice alone.
// The collapsed map's light at si (the paper's Section 2.2): every one of its lights, each
// with its shadow ray, sum_i f(wo, w_i) E_i V(w_i), where E_i = L(w_i) / (p(w_i) N) for
// Algorithm 1's draws or a median-cut region's power. The same set at every point: no noise
// between neighbours, a bias that falls as N grows.
template <class Tracer>
ENVGI_HD Color collapsedMapLighting(const SceneView& sc, const Tracer& tracer, const SurfaceInteraction& si,
                                    const Bsdf& bsdf, const Bsdf* partner, Vec3f woLocal, uint64_t* rayCount) {
  Color L(0.f);
  if (!sc.hasEnvironment || bsdfMixIsDelta(bsdf, partner)) return L;
  for (int i = 0; i < sc.env.pointCount; ++i) {
    const DirectionalLight& light = sc.env.points[i];
    Vec3f wiLocal = si.shading.toLocal(light.dir);
    float pdf;
    Color f = bsdfMixEvalPdf(bsdf, partner, si.partnerWeight, woLocal, wiLocal, &pdf);
    if (isBlack(f) || isBlack(light.irradiance)) continue;
    ++*rayCount;
    if (tracer.occluded(offsetRayOrigin(si.p, si.ng, light.dir, si.t), light.dir, INFINITY)) continue;
    L += f * light.irradiance;
  }
  return L;
}

template <class Tracer>
ENVGI_HD Color directLighting(const SceneView& sc, const Tracer& tracer, const SurfaceInteraction& si, Vec3f wo,
                              Sampler& smp, EnvStrategy strategy, int emitterSamples, int bsdfSamples,
                              uint64_t* rayCount, bool skipDelta = false, bool mixBlend = false,
                              MisHeuristic heuristic = MisHeuristic::Power) {
  Color L(0.f);
  BsdfScratch textured, texturedPartner;
  const Bsdf& bsdf = sc.bsdfAt(si, &textured);
  const Bsdf* partner = mixBlend ? sc.partnerAt(si, &texturedPartner) : nullptr;
  Vec3f woLocal = si.shading.toLocal(wo);
  Vec3f axis = envSamplingAxis(si, wo, bsdf);
  float nE = float(emitterSamples), nB = float(bsdfSamples);

  for (int i = 0; i < emitterSamples; ++i)
    L += sampleLd(sc, tracer, si, bsdf, woLocal, axis, strategy, nE, nB, heuristic, smp, rayCount, partner);
  if (strategy == EnvStrategy::PointsAll) L += collapsedMapLighting(sc, tracer, si, bsdf, partner, woLocal, rayCount);

  for (int j = 0; j < bsdfSamples; ++j) {
    BsdfSample bs;
    const SampledParts parts{sc};
    const BsdfDraws u = drawBsdf(bsdf, smp, parts);
    if (!parts.bsdfSample(bsdf, woLocal, u.uc, u.ub, &bs) || (skipDelta && bs.delta)) continue;
    if (partner) bsdfMixReweight(*partner, si.partnerWeight, woLocal, &bs);
    Vec3f wi = si.shading.toWorld(bs.wi);
    Ray r2{offsetRayOrigin(si.p, si.ng, wi, si.t), wi, INFINITY};
    Hit h2;
    ++*rayCount;
    Color Le(0.f);
    float lightPdf = 0.f;
    if (!tracer.intersect(r2, &h2)) {
      if (!sc.hasEnvironment || !envSeenByBsdfSampling(strategy, bs.delta)) continue;
      Le = envRadianceAndPdf(sc, strategy, wi, axis, &lightPdf);
    } else {
      SurfaceInteraction s2 = sc.interaction(r2, h2);
      Le = sc.emitted(s2, -wi);
      if (isBlack(Le)) continue;
      lightPdf = areaLightPdf(sc, s2.light, si.p, s2.p, s2.ng);
    }
    float w = (bs.delta || nE == 0.f) ? 1.f : misHeuristic(heuristic, nB, bs.pdf, nE, lightPdf);
    L += bs.weight * Le * (w / nB);
  }
  return L;
}

template <class Tracer>
ENVGI_HD Color directTrace(const SceneView& sc, const Tracer& tracer, Ray ray, Sampler& smp, const DirectParams& dp,
                           uint64_t* rayCount) {
  Hit h;
  ++*rayCount;
  if (!tracer.intersect(ray, &h))
    return (sc.hasEnvironment && !dp.hideEmitters) ? sc.env.eval(ray.d) : Color(0.f);
  SurfaceInteraction si = sc.interaction(ray, h);
  Vec3f wo = -ray.d;
  Color L = dp.hideEmitters ? Color(0.f) : sc.emitted(si, wo);
  return L + directLighting(sc, tracer, si, wo, smp, dp.envStrategy, dp.emitterSamples, dp.bsdfSamples, rayCount,
                            false, true, dp.heuristic);
}

}  // namespace envgi
