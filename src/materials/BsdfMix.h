// Two BSDFs of one shading frame mixed as (1 - w) a + w b: Mitsuba's blendbsdf evaluated whole
// (SceneView::blendPartner says where). `a` is the one whose sample the path follows, chosen
// with the chance 1 - w; the mix's density is then that of one-sample MIS over the two.
#pragma once

#include "materials/Bsdf.h"

namespace envgi {

// b's part, out of line on the GPU: only blends reach it, and a second inlined copy of
// bsdfEvalPdf would grow every kernel that shades (as texturedCopy, docs/gpu.md).
inline ENVGI_HD_NOINLINE Color bsdfPartnerEvalPdf(const Bsdf& b, Vec3f wo, Vec3f wi, float* pdf) {
  return bsdfEvalPdf(b, wo, wi, pdf);
}

// f and, through *pdf, the density of non-delta directions: a's alone without b.
ENVGI_INLINE Color bsdfMixEvalPdf(const Bsdf& a, const Bsdf* b, float wb, Vec3f wo, Vec3f wi, float* pdf) {
  Color f = bsdfEvalPdf(a, wo, wi, pdf);
  if (!b) return f;
  float pb;
  Color fb = bsdfPartnerEvalPdf(*b, wo, wi, &pb);
  *pdf = (1.f - wb) * *pdf + wb * pb;
  return f * (1.f - wb) + fb * wb;
}

// Whether next-event estimation has nothing to evaluate: every lobe of the mix is a delta.
ENVGI_INLINE bool bsdfMixIsDelta(const Bsdf& a, const Bsdf* b) { return bsdfIsDelta(a) && (!b || bsdfIsDelta(*b)); }

// a's sample s (a drawn with the chance 1 - wb) as a sample of the mix: a direction off a's delta
// lobes takes the mix's value over the mix's density; a delta one keeps its weight, the chance of
// choosing a cancelling a's share of the mix. a's value there is s's weight times its density
// (BsdfChi2.SampleMatchesPdf holds every BSDF to that), so only b is evaluated.
ENVGI_INLINE void bsdfMixReweight(const Bsdf& b, float wb, Vec3f wo, BsdfSample* s) {
  if (s->delta) return;
  float pb;
  Color fb = bsdfPartnerEvalPdf(b, wo, s->wi, &pb);
  const float pdf = (1.f - wb) * s->pdf + wb * pb;
  s->weight = pdf > 0.f ? (s->weight * (s->pdf * (1.f - wb)) + fb * wb) / pdf : Color(0.f);
  s->pdf = pdf;
}

}  // namespace envgi
