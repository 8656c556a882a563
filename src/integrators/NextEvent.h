// Next-event estimation at one shading point: a light sample (the map by the chosen strategy,
// or an area light) with its shadow ray, MIS-weighted against nB BSDF samples out of nE light
// samples (power heuristic, Veach's Eq. 9.13; the paper's Eq. 6 with two strategies). The one
// copy that path, direct and the photon mappers share.
#pragma once

#include "lights/LightSampling.h"
#include "materials/BsdfMix.h"
#include "sampling/Mis.h"
#include "sampling/Sampler.h"

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

// The BSDF's value and density for a light direction, worked out ahead (the CPU's
// RoundLanes::evalRoughPlastic, a round's rough plastic evaluations in vector lanes): bsdfEvalPdf's
// for wi in the shading frame, which prepareLd takes where its direction is wi to the bit.
struct BsdfEvalAhead {
  Vec3f wi;
  Color f;
  float pdf = 0.f;
  bool made = false;
};

// A light sample's draws, in the order the sampler lays them out: the dimension a choice of the
// light's kind once took (skipped: sampleLight picks the kind by uL.x, and later draws keep
// their dimensions), the light's pair, and the area light's second pair (skipped where the map
// is the only light). uLAhead: the light's pair drawn elsewhere for that dimension (an
// executor's lanes, at bounceLayout's offset), stepped over here.
struct LightDraws {
  Vec2f uL, uL2;
};
ENVGI_HD inline LightDraws drawLight(const SceneView& sc, Sampler& smp, const Vec2f* uLAhead = nullptr) {
  LightDraws u;
  smp.skip1D();
  if (uLAhead) u.uL = *uLAhead, smp.skip2D();
  else u.uL = smp.get2D();
  u.uL2 = smp.get2DIf(!(sc.envSelectProb() == 1.f));  // sampleLight takes the map for any uL then
  return u;
}

// One light sample from the draws u. `partner` is a blend's other material (sc.partnerAt(si)),
// evaluated beside bsdf at si.partnerWeight (materials/BsdfMix.h). productDrawn: the map's
// product draw for u.uL, made ahead (sampleLight's); evalAhead: the BSDF (without a partner)
// evaluated ahead for the direction that draw gives.
ENVGI_HD inline LightSampleLd prepareLd(const SceneView& sc, const SurfaceInteraction& si, const Bsdf& bsdf,
                                        Vec3f woLocal, Vec3f axis, EnvStrategy strategy, float nE, float nB,
                                        MisHeuristic heuristic, const LightDraws& u, const Bsdf* partner = nullptr,
                                        const ProductDraw* productDrawn = nullptr,
                                        const BsdfEvalAhead* evalAhead = nullptr) {
  LightSampleLd out;
  LightSample ls;
  if (bsdfMixIsDelta(bsdf, partner) || !sampleLight(sc, si, axis, strategy, u.uL, u.uL2, &ls, productDrawn))
    return out;
  Vec3f wiLocal = si.shading.toLocal(ls.dir);
  float bsdfPdfOfLight;
  Color f;
  if (evalAhead && evalAhead->made && !partner && sameBits(wiLocal, evalAhead->wi)) {
    f = evalAhead->f, bsdfPdfOfLight = evalAhead->pdf;
  } else {
    f = bsdfMixEvalPdf(bsdf, partner, si.partnerWeight, woLocal, wiLocal, &bsdfPdfOfLight);
  }
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
  float w = nB > 0.f && !ls.delta ? misHeuristic(heuristic, nE, ls.pdf, nB, bsdfPdfOfLight) : 1.f;
  out.value = f * ls.radiance * (w / (ls.pdf * nE));
  out.needsRay = true;
  return out;
}

// The sample's contribution once its shadow ray's answer is known.
ENVGI_HD inline Color resolvedLd(const LightSampleLd& ld, bool occluded) {
  return ld.needsRay && !occluded ? ld.value : Color(0.f);
}

// bsdfSample's answer for a draw made ahead, worked out ahead too (the CPU's
// RoundLanes::sampleRoughPlastic, a round's rough plastic samples in vector lanes).
struct BsdfSampleAhead {
  BsdfSample s;
  bool ok = false;    // bsdfSample's return
  bool made = false;  // s and ok hold bsdfSample's answer for the bounce's BSDF draws
};

// A bounce's BSDF draws as path and direct take them: uc only where bsdfSample reads it beside
// ub (skipped, not drawn, elsewhere, so later draws keep their dimensions), then the pair.
// ubAhead: the pair drawn elsewhere for that dimension (an executor's lanes), stepped over here.
struct BsdfDraws {
  float uc = 0.f;
  Vec2f ub;
};
ENVGI_HD inline BsdfDraws drawBsdf(const Bsdf& bsdf, Sampler& smp, const Vec2f* ubAhead = nullptr) {
  BsdfDraws u;
  u.uc = smp.get1DIf(bsdfReadsUcBesideU(bsdf));
  if (ubAhead) u.ub = *ubAhead, smp.skip2D();
  else u.ub = smp.get2D();
  return u;
}

// The BSDF sampled from the draws u, the lobe from ub where the BSDF can take it from there
// (bsdfLobeFromU). sampled: bsdfSample's answer for these draws, where it was worked out
// ahead (uc-free: sampleRoughPlastic's).
ENVGI_HD inline bool drawBsdfSample(const Bsdf& bsdf, Vec3f woLocal, const BsdfDraws& u, BsdfSample* bs,
                                    const BsdfSampleAhead* sampled = nullptr) {
  if (sampled && sampled->made) {
    *bs = sampled->s;
    return sampled->ok;
  }
  return bsdfSample(bsdf, woLocal, u.uc, u.ub, bs, true);
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
