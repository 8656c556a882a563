// Next-event estimation at one shading point: a light sample (the map by the chosen strategy,
// or an area light) with its shadow ray, MIS-weighted against nB BSDF samples out of nE light
// samples (power heuristic, Veach's Eq. 9.13; the paper's Eq. 6 with two strategies). The one
// copy that path, direct and the photon mappers share.
#pragma once

#include "lights/LightSampling.h"
#include "sampling/Mis.h"
#include "sampling/Sampler.h"

namespace envgi {

// Returns f * L * w / (pdf * nE) for one light sample, zero if it is blocked or the BSDF is a
// pure delta. Its three sample dimensions are drawn whatever happens, so sequences stay
// aligned across pixels.
template <class Tracer>
ENVGI_HD Color sampleLd(const SceneView& sc, const Tracer& tracer, const SurfaceInteraction& si, const Bsdf& bsdf,
                        Vec3f woLocal, Vec3f axis, EnvStrategy strategy, float nE, float nB, Sampler& smp,
                        uint64_t* rayCount) {
  float uSel = smp.get1D();
  Vec2f uL = smp.get2D(), uL2 = smp.get2D();
  LightSample ls;
  if (bsdfIsDelta(bsdf) || !sampleLight(sc, si, axis, strategy, uSel, uL, uL2, &ls)) return Color(0.f);
  Vec3f wiLocal = si.shading.toLocal(ls.dir);
  Color f = bsdfEval(bsdf, woLocal, wiLocal);
  if (isBlack(f) || isBlack(ls.radiance)) return Color(0.f);
  Vec3f o = offsetRayOrigin(si.p, si.ng, ls.dir, si.t);
  float tMax = ls.environment ? INFINITY : ls.dist * (1.f - 1e-4f) - length(o - si.p);
  ++*rayCount;
  if (tracer.occluded(o, ls.dir, tMax)) return Color(0.f);
  float w = nB > 0.f && !ls.delta ? powerHeuristic(nE, ls.pdf, nB, bsdfPdf(bsdf, woLocal, wiLocal)) : 1.f;
  return f * ls.radiance * (w / (ls.pdf * nE));
}

}  // namespace envgi
