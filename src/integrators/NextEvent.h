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

// Its sample dimensions are taken whatever happens, so sequences stay aligned across pixels.
// `partner` is a blend's other material (sc.partnerAt(si)), evaluated beside bsdf at
// si.partnerWeight (materials/BsdfMix.h). The kind of light is picked by uL.x (sampleLight), so
// the dimension a choice of its own once took is skipped, as is the area light's second pair
// where the map is the only light (the image stays the same there). uLDrawn: the light's 2D
// draw where the caller took it ahead from a copy of smp (lightDrawOf), stepped over here;
// productDrawn: the map's product draw for it, made ahead (sampleLight's); evalAhead: the BSDF
// (without a partner) evaluated ahead for the direction that draw gives.
ENVGI_HD inline LightSampleLd prepareLd(const SceneView& sc, const SurfaceInteraction& si, const Bsdf& bsdf,
                                        Vec3f woLocal, Vec3f axis, EnvStrategy strategy, float nE, float nB,
                                        MisHeuristic heuristic, Sampler& smp, const Bsdf* partner = nullptr,
                                        const Vec2f* uLDrawn = nullptr, const ProductDraw* productDrawn = nullptr,
                                        const BsdfEvalAhead* evalAhead = nullptr) {
  LightSampleLd out;
  const bool mapOnly = sc.envSelectProb() == 1.f;  // sampleLight then takes the map for any uL
  smp.skip1D();
  Vec2f uL;
  if (uLDrawn) uL = *uLDrawn, smp.skip2D();
  else uL = smp.get2D();
  Vec2f uL2 = smp.get2DIf(!mapOnly);
  LightSample ls;
  if (bsdfMixIsDelta(bsdf, partner) || !sampleLight(sc, si, axis, strategy, uL, uL2, &ls, productDrawn)) return out;
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

// A 2D draw made ahead (the CPU's RoundLanes::drawAhead, a round's draws in vector lanes) for
// the dimension pair that starts at dim; taken where the sampler stands there, drawn afresh
// anywhere else, so an executor that guesses the dimension wrong loses time, never the image.
struct Draw2DAhead {
  Vec2f u;
  uint32_t dim = ~0u;
};
ENVGI_HD inline Vec2f get2DOrAhead(Sampler& smp, const Draw2DAhead* ahead) {
  if (ahead && ahead->dim == smp.dim) {
    smp.skip2D();
    return ahead->u;
  }
  return smp.get2D();
}

// The light's 2D draw prepareLd will take from smp as it stands, taken from a copy (or the
// draw made ahead for that dimension, if it is one: get2DOrAhead).
ENVGI_HD inline Vec2f lightDrawOf(const Sampler& smp, const Draw2DAhead* ahead = nullptr) {
  Sampler peek = smp;
  peek.skip1D();
  return get2DOrAhead(peek, ahead);
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
  bool made = false;  // s and ok hold bsdfSample's answer for the draw ahead (Draw2DAhead)
};

// A bounce's BSDF draw as path and direct take it: uc only where bsdfSample reads it beside ub
// (skipped, not drawn, elsewhere, so later draws keep their dimensions), and the lobe from ub
// where the BSDF can take it from there (bsdfLobeFromU).
// ubAhead: the pair's draw made ahead, if any (get2DOrAhead); sampled: bsdfSample's answer for
// it, if that was worked out ahead, taken where the draw is (it is uc-free: sampleRoughPlastic's).
ENVGI_HD inline bool drawBsdfSample(const Bsdf& bsdf, Vec3f woLocal, Sampler& smp, BsdfSample* bs,
                                    const Draw2DAhead* ubAhead = nullptr, const BsdfSampleAhead* sampled = nullptr) {
  float uc = smp.get1DIf(bsdfReadsUcBesideU(bsdf));
  if (sampled && sampled->made && ubAhead && ubAhead->dim == smp.dim) {
    smp.skip2D();
    *bs = sampled->s;
    return sampled->ok;
  }
  Vec2f ub = get2DOrAhead(smp, ubAhead);
  return bsdfSample(bsdf, woLocal, uc, ub, bs, true);
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
  LightSampleLd ld = prepareLd(sc, si, bsdf, woLocal, axis, strategy, nE, nB, heuristic, smp, partner);
  return resolvedLd(ld, shadowRayBlocked(tracer, ld, rayCount));
}

}  // namespace envgi
