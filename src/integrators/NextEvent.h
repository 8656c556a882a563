// Next-event estimation at one shading point: a light sample (the map by the chosen strategy,
// or an area light) with its shadow ray, MIS-weighted against nB BSDF samples out of nE light
// samples (power heuristic, Veach's Eq. 9.13; the paper's Eq. 6 with two strategies). The one
// copy that path, direct and the photon mappers share.
#pragma once

#include "integrators/BounceParts.h"
#include "sampling/Mis.h"

namespace envgi {

// One light sample before its shadow ray: f * L * w / (pdf * nE), which counts only if the ray
// from o along d (to tMax) is unblocked; no ray (and nothing) for a sample below the surface, a
// black one or a pure delta BSDF.
struct LightSampleLd {
  Color value;
  Vec3f o, d;
  float tMax = 0.f;
  bool needsRay = false;
};

// Where a light sample's draws lie past the sampler's position: the dimension a choice of the
// light's kind once took (skipped: sampleLight picks the kind by uL.x, and later draws keep
// their dimensions), the light's pair, and the area light's second pair (skipped where the map
// is the only light). drawLight draws at these offsets, and so does any batch of the same draws.
struct LightDrawLayout {
  static constexpr uint32_t pair = 1, second = 3, size = 5;
};
struct LightDraws {
  Vec2f uL, uL2;
};
template <class Parts>
ENVGI_HD inline LightDraws drawLight(const SceneView& sc, Sampler& smp, const Parts& parts) {
  const uint32_t base = smp.dim;
  LightDraws u;
  smp.skipTo(base + LightDrawLayout::pair);
  u.uL = parts.pair(smp, BouncePair::Light);
  smp.skipTo(base + LightDrawLayout::second);
  u.uL2 = smp.get2DIf(!(sc.envSelectProb() == 1.f));  // sampleLight takes the map for any uL then
  return u;
}
ENVGI_HD inline LightDraws drawLight(const SceneView& sc, Sampler& smp) { return drawLight(sc, smp, SampledParts{sc}); }

// A light sample ls's contribution before its shadow ray, given the BSDF's value f and density
// bsdfPdf in its direction: MIS-weighted against nB BSDF samples out of nE light samples.
ENVGI_HD inline LightSampleLd lightSampleLd(const SurfaceInteraction& si, const LightSample& ls, Color f,
                                            float bsdfPdf, float nE, float nB, MisHeuristic heuristic) {
  LightSampleLd out;
  if (isBlack(f) || isBlack(ls.radiance)) return out;
  out.o = offsetRayOrigin(si.p, si.ng, ls.dir, si.t);
  out.d = ls.dir;
  out.tMax = INFINITY;
  if (!ls.environment && ls.dist < INFINITY) {
    // Aimed from the offset origin at the light's point itself, and stopped short of it: a ray
    // kept parallel to ls.dir from the offset origin meets the light's plane short of the point
    // where it comes in at a grazing angle, so the light shadowed itself there (a floor edge-on
    // to a tilted square light lost all its light: LightSampling.ShadowRaysReachAGrazingLight).
    Vec3f to = si.p + ls.dir * ls.dist - out.o;
    float len = length(to);
    if (!(len > 0.f)) return out;  // the light's point is the origin itself: nothing to carry
    out.d = to / len;
    out.tMax = len * (1.f - 1e-4f);
  }
  float w = nB > 0.f && !ls.delta ? misHeuristic(heuristic, nE, ls.pdf, nB, bsdfPdf) : 1.f;
  out.value = f * ls.radiance * (w / (ls.pdf * nE));
  out.needsRay = true;
  return out;
}

// One light sample from the draws u, its parts from parts. `partner` is a blend's other
// material (sc.partnerAt(si)), evaluated beside bsdf at si.partnerWeight (materials/BsdfMix.h).
// Out of line on the GPU, where the path kernel and directLighting each inlined it spilt more.
template <class Parts>
inline ENVGI_HD_NOINLINE LightSampleLd prepareLd(const Parts& parts, const SurfaceInteraction& si, const Bsdf& bsdf,
                                        Vec3f woLocal, Vec3f axis, EnvStrategy strategy, float nE, float nB,
                                        MisHeuristic heuristic, const LightDraws& u, const Bsdf* partner) {
  LightSample ls;
  if (bsdfMixIsDelta(bsdf, partner) || !parts.lightSample(si, axis, strategy, u.uL, u.uL2, &ls)) return {};
  float bsdfPdf;
  const Color f = parts.bsdfValue(bsdf, partner, si, woLocal, si.shading.toLocal(ls.dir), &bsdfPdf);
  return lightSampleLd(si, ls, f, bsdfPdf, nE, nB, heuristic);
}
ENVGI_HD inline LightSampleLd prepareLd(const SceneView& sc, const SurfaceInteraction& si, const Bsdf& bsdf,
                                        Vec3f woLocal, Vec3f axis, EnvStrategy strategy, float nE, float nB,
                                        MisHeuristic heuristic, const LightDraws& u, const Bsdf* partner = nullptr) {
  return prepareLd(SampledParts{sc}, si, bsdf, woLocal, axis, strategy, nE, nB, heuristic, u, partner);
}

// The sample's contribution once its shadow ray's answer is known.
ENVGI_HD inline Color resolvedLd(const LightSampleLd& ld, bool occluded) {
  return ld.needsRay && !occluded ? ld.value : Color(0.f);
}

// Where a BSDF sample's draws lie past the sampler's position: uc, only where bsdfSample reads
// it beside the pair (skipped, not drawn, elsewhere, so later draws keep their dimensions), then
// the pair. drawBsdf draws at these offsets, and so does any batch of the same draws.
struct BsdfDrawLayout {
  static constexpr uint32_t lobe = 0, pair = 1, size = 3;
};
struct BsdfDraws {
  float uc = 0.f;
  Vec2f ub;
};
template <class Parts>
ENVGI_HD inline BsdfDraws drawBsdf(const Bsdf& bsdf, Sampler& smp, const Parts& parts) {
  const uint32_t base = smp.dim;
  BsdfDraws u;
  smp.skipTo(base + BsdfDrawLayout::lobe);
  u.uc = smp.get1DIf(bsdfReadsUcBesideU(bsdf));
  smp.skipTo(base + BsdfDrawLayout::pair);
  u.ub = parts.pair(smp, BouncePair::Bsdf);
  return u;
}

// Traces the sample's shadow ray, if it has one (counted in *rayCount): whether it is blocked.
template <class Tracer>
ENVGI_HD bool shadowRayBlocked(const Tracer& tracer, const LightSampleLd& ld, uint64_t* rayCount) {
  if (!ld.needsRay) return false;
  ++*rayCount;
  return tracer.occluded(ld.o, ld.d, ld.tMax);
}

// prepareLd with its shadow ray traced now: f * L * w / (pdf * nE) for one light sample, zero if
// it is blocked.
template <class Tracer>
ENVGI_HD Color sampleLd(const SceneView& sc, const Tracer& tracer, const SurfaceInteraction& si, const Bsdf& bsdf,
                        Vec3f woLocal, Vec3f axis, EnvStrategy strategy, float nE, float nB, MisHeuristic heuristic,
                        Sampler& smp, uint64_t* rayCount, const Bsdf* partner = nullptr) {
  LightSampleLd ld = prepareLd(sc, si, bsdf, woLocal, axis, strategy, nE, nB, heuristic, drawLight(sc, smp), partner);
  return resolvedLd(ld, shadowRayBlocked(tracer, ld, rayCount));
}

}  // namespace envgi
