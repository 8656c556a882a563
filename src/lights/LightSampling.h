// Next-event estimation: choosing the environment, an area light or a delta light, and the
// densities a BSDF-sampled direction would have had under that choice (for MIS).
#pragma once

#include "scene/SceneView.h"

namespace envgi {

struct LightSample {
  Vec3f dir;            // from the shading point towards the light
  float dist = INFINITY;
  Color radiance;
  float pdf = 0.f;      // solid angle, selection included; a pmf for a delta light
  bool environment = false;
  bool delta = false;   // a collapsed-map or delta light: no MIS, BSDF sampling cannot find it
};

// The cosine and product strategies sample about the shading normal on the side the viewer is
// on, where a reflecting BSDF is non-zero; a BSDF that transmits gets the zero axis, which
// those strategies read as the whole sphere.
ENVGI_INLINE Vec3f envSamplingAxis(const SurfaceInteraction& si, Vec3f wo, const Bsdf& bsdf) {
  if (bsdfTransmits(bsdf)) return Vec3f(0.f);
  return dot(si.shading.n, wo) >= 0.f ? si.shading.n : -si.shading.n;
}

// Whether a BSDF-sampled ray that escapes to the map counts: not where next-event estimation
// already took the whole map as collapsed-map lights (a delta bounce still sees the map).
ENVGI_INLINE bool envSeenByBsdfSampling(EnvStrategy s, bool prevDelta) { return prevDelta || !isCollapsedMap(s); }

// The map's radiance along an escaping BSDF-sampled direction and, through *lightPdf, the
// density next-event estimation would have drawn it with (selection included).
ENVGI_INLINE Color envRadianceAndPdf(const SceneView& sc, EnvStrategy s, Vec3f dir, Vec3f axis, float* lightPdf) {
  Color Le = sc.env.evalWithPdf(s, dir, axis, lightPdf);
  *lightPdf *= sc.envSelectProb();
  return Le;
}
// That density alone, where dir's (u, v) on the map is known.
ENVGI_INLINE float envLightPdfAt(const SceneView& sc, EnvStrategy s, Vec3f dir, Vec2f uv, Vec3f axis) {
  return sc.env.pdfAtUV(s, dir, uv, axis) * sc.envSelectProb();
}

// Solid-angle density of reaching light primitive `light` at point lp (normal ln) from p.
ENVGI_INLINE float areaLightPdf(const SceneView& sc, int light, Vec3f p, Vec3f lp, Vec3f ln) {
  if (light < 0 || sc.lightCount == 0) return 0.f;
  Vec3f d = lp - p;
  float dist2 = lengthSq(d);
  float cosL = std::fabs(dot(ln, d)) / std::sqrt(dist2);
  if (cosL <= 0.f) return 0.f;
  return sc.areaSelectProb() * sc.lightSelect.pmf(light) * sc.lightAreaPdf(sc.lights[light], lp) * dist2 / cosL;
}

// sampleLight's choice of a delta or an area light (u.x at or past the map's share pe). Out of
// line on the GPU: most scenes are lit by the map alone, and this code in the path kernel's hot
// loop cost instruction fetch (docs/gpu.md).
inline ENVGI_HD_NOINLINE bool sampleDeltaOrAreaLight(const SceneView& sc, const SurfaceInteraction& si, float pe,
                                                     Vec2f u, Vec2f u2, LightSample* ls) {
  const float uSel = u.x;
  float pa = sc.areaSelectProb();
  if (sc.deltaLightCount > 0 && !(uSel < pe + pa)) {
    // One delta light, all alike; the kind's share of uSel picks it.
    float pd = sc.deltaSelectProb();
    int n = sc.deltaLightCount;
    const DeltaLight& l = sc.deltaLights[uniformLightIndex((uSel - pe - pa) / pd, n)];
    ls->radiance = deltaLightIncident(l, si.p, &ls->dir, &ls->dist);
    ls->pdf = pd / float(n);
    ls->environment = false;
    ls->delta = true;
    return !isBlack(ls->radiance);
  }
  if (sc.lightCount == 0) return false;
  float pmf, areaPdf;
  Vec3f p, n;
  Color Le;
  sampleAreaLight(sc, u2, Vec2f(stretchedDraw(uSel, pe, pa), u.y), &pmf, &p, &n, &Le, &areaPdf);
  Vec3f d = p - si.p;
  float dist2 = lengthSq(d);
  if (dist2 <= 0.f) return false;
  float dist = std::sqrt(dist2);
  d = d / dist;
  float cosL = -dot(n, d);
  if (cosL <= 0.f) return false;  // one-sided emitters face along their normal
  ls->dir = d;
  ls->dist = dist;
  ls->radiance = Le;
  ls->pdf = pa * pmf * areaPdf * dist2 / cosL;
  ls->environment = false;
  ls->delta = false;
  return ls->pdf > 0.f;
}

// Whether u picks the map, with *u then stretched to the map's own draw (sampleLight's choice).
// The whole collapsed map is added at every point (collapsedMapLighting): a light sample that
// picks it carries nothing, and the other lights' shares stay unbiased.
ENVGI_INLINE bool lightDrawPicksMap(const SceneView& sc, EnvStrategy strategy, Vec2f* u) {
  const float pe = sc.envSelectProb();
  if (!(u->x < pe) || strategy == EnvStrategy::PointsAll) return false;
  if (pe < 1.f) u->x = stretchedDraw(u->x, 0.f, pe);
  return true;
}

// The map's sample es as a light sample (its selection included).
ENVGI_INLINE bool mapLightSample(const SceneView& sc, const EnvSample& es, LightSample* ls) {
  if (!(es.pdf > 0.f)) return false;
  ls->dir = es.dir;
  ls->dist = INFINITY;
  ls->radiance = es.radiance;
  ls->pdf = es.pdf * sc.envSelectProb();
  ls->environment = true;
  ls->delta = es.delta;
  return true;
}

// u.x picks the kind of light by the kinds' shares and is then stretched back over [0, 1) for
// that light's own draw (sample reuse, as Mitsuba's emitter selection does): the draws that land
// on one kind keep the sequence's strata, where a draw of their own handed each kind a random
// subset of the points. With the map the only light, u is the map's draw as it is.
ENVGI_INLINE bool sampleLight(const SceneView& sc, const SurfaceInteraction& si, Vec3f axis, EnvStrategy strategy,
                              Vec2f u, Vec2f u2, LightSample* ls) {
  const float pe = sc.envSelectProb();
  if (!(u.x < pe)) return sampleDeltaOrAreaLight(sc, si, pe, u, u2, ls);
  return lightDrawPicksMap(sc, strategy, &u) && mapLightSample(sc, sc.env.sample(strategy, u, axis), ls);
}

}  // namespace envgi
