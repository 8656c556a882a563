// Mitsuba 3's `principled` BSDF (its src/bsdfs/principled.cpp, after Burley's 2015 Disney BSDF):
// a diffuse base with retro-reflection, sheen and a fake subsurface ("flatness"), a GGX
// specular lobe whose Fresnel blends dielectric, tinted and metallic, a GTR1 clearcoat, and
// rough glass ("spec_trans"). The values are Mitsuba's term by term, so that its scenes render
// alike; the masking is envgi's height-correlated Smith G, as in every rough BSDF here
// (docs/scene-format.md). Directions are local (z = shading normal): o towards the viewer, i towards
// the light (Mitsuba's si.wi and wo). eval() carries |cos theta_i|, as everywhere in Bsdf.h.
#pragma once

#include "materials/Fresnel.h"
#include "materials/Microfacet.h"
#include "sampling/Warp.h"

namespace envgi {

// What the principled BSDF adds to Bsdf's own fields: its base_color is Bsdf::reflectance, its
// eta Bsdf::ior. The three rates weight its lobes in sampling (Mitsuba's *_sampling_rate).
struct PrincipledParams {
  float roughness = 0.5f, anisotropic = 0.f, metallic = 0.f, specTrans = 0.f, specTint = 0.f;
  float sheen = 0.f, sheenTint = 0.f, flatness = 0.f, clearcoat = 0.f, clearcoatGloss = 0.f;
  float specularRate = 1.f, clearcoatRate = 1.f, diffuseRate = 1.f;
};

// eta from Mitsuba's `specular` (the reflectance at normal incidence is 0.08 specular).
ENVGI_INLINE float principledEtaFromSpecular(float specular) {
  return 2.f / (1.f - std::sqrt(0.08f * specular)) - 1.f;
}

namespace principled {

ENVGI_INLINE float schlickWeight(float c) {
  float m = clampf(1.f - c, 0.f, 1.f);
  return sqr(sqr(m)) * m;
}
// The weight of Schlick's approximation R0 + (1 - R0) w at cos c on an interface of index eta,
// from inside taken at the refracted angle (Mitsuba's calc_schlick).
ENVGI_INLINE float interfaceWeight(float c, float eta) {
  float etaIt = c >= 0.f ? eta : 1.f / eta;
  if (etaIt > 1.f) return schlickWeight(std::fabs(c));
  return schlickWeight(safeSqrt(1.f - (1.f - c * c) / (etaIt * etaIt)));
}
ENVGI_INLINE Color schlick(Color r0, float w) { return r0 * (1.f - w) + Color(w); }

// GGX roughness from roughness and anisotropic (Mitsuba's calc_dist_params).
ENVGI_INLINE MicrofacetDistribution specularLobe(const PrincipledParams& p) {
  float r2 = p.roughness * p.roughness, aspect = std::sqrt(1.f - 0.9f * p.anisotropic);
  return {fmaxf(1e-3f, r2 / aspect), fmaxf(1e-3f, r2 * aspect), MicrofacetType::GGX};
}

// The clearcoat's GTR1 distribution (Burley 2012), its roughness between 0.1 and 0.001.
ENVGI_INLINE float clearcoatAlpha(const PrincipledParams& p) { return lerpf(p.clearcoatGloss, 0.1f, 0.001f); }
ENVGI_INLINE float gtr1D(float a, float cosH) {
  float a2 = a * a;
  float r = (a2 - 1.f) / (kPi * std::log(a2) * (1.f + (a2 - 1.f) * cosH * cosH));
  return r * cosH > 1e-20f ? r : 0.f;
}
ENVGI_INLINE Vec3f gtr1Sample(float a, Vec2f u) {
  float a2 = a * a, phi = 2.f * kPi * u.x;
  float cos2 = (1.f - std::pow(a2, 1.f - u.y)) / (1.f - a2);
  float sinT = safeSqrt(1.f - cos2), cosT = safeSqrt(cos2);
  return Vec3f(std::cos(phi) * sinT, std::sin(phi) * sinT, cosT);
}
// The clearcoat's separable Smith G1 at a fixed roughness 0.25, zero for a facet seen from behind.
ENVGI_INLINE float clearcoatG1(Vec3f v, Vec3f h) {
  if (dot(v, h) * v.z <= 0.f) return 0.f;
  if (v.z == 1.f) return 1.f;
  float c2 = v.z * v.z, tan2 = (1.f - c2) / c2;
  return 2.f / (1.f + std::sqrt(1.f + 0.0625f * tan2));
}

// The weights of the diffuse base (with its sheen) and of the glass; the metal takes the rest.
ENVGI_INLINE float baseWeight(const PrincipledParams& p) { return (1.f - p.metallic) * (1.f - p.specTrans); }
ENVGI_INLINE float glassWeight(const PrincipledParams& p) { return (1.f - p.metallic) * p.specTrans; }

// What eval and pdf share for one pair of directions: the half vector (generalised for
// refraction, facing +z), the dielectric Fresnel there, and which lobes the pair can belong to.
struct Pair {
  Vec3f h;
  float F, etaPath;
  bool reflect, front, specReflect, specTransmit;  // the last two: macro and micro surface agree
};
ENVGI_INLINE bool pairOf(float eta, Vec3f o, Vec3f i, Pair* q) {
  float co = o.z, ci = i.z;
  if (co == 0.f || co * ci == 0.f) return false;
  q->reflect = co * ci > 0.f;
  q->front = co > 0.f;
  q->etaPath = q->front ? eta : 1.f / eta;
  Vec3f h = o + i * (q->reflect ? 1.f : q->etaPath);
  if (!(lengthSq(h) > 0.f)) return false;
  h = normalize(h);
  if (h.z < 0.f) h = -h;
  q->h = h;
  q->F = fresnelDielectric(dot(o, h), eta);
  float s = q->front ? 1.f : -1.f, oh = dot(o, h) * s, ih = dot(i, h) * s;
  q->specReflect = q->reflect && oh > 0.f && ih > 0.f;
  q->specTransmit = !q->reflect && oh > 0.f && ih < 0.f;
  return true;
}

// The lobes' sampling probabilities, normalised; given F at the specular lobe's microfacet.
// The specular pair sums to the specular rate whatever F is, so the lobe choice in sample()
// is the one pdf() states.
struct LobeProbs {
  float specReflect, specTransmit, clearcoat, diffuse;
};
ENVGI_INLINE LobeProbs lobeProbs(const PrincipledParams& p, bool front, float F) {
  float btdf = glassWeight(p), brdf = baseWeight(p);
  LobeProbs l;
  if (front) {
    l.specReflect = p.specularRate * (1.f - btdf * (1.f - F));
    l.specTransmit = p.specularRate * btdf * (1.f - F);
    l.clearcoat = 0.25f * p.clearcoat * p.clearcoatRate;
    l.diffuse = brdf * p.diffuseRate;
  } else {  // from inside: the glass's interface only
    l.specReflect = F;
    l.specTransmit = 1.f - F;
    l.clearcoat = l.diffuse = 0.f;
  }
  float total = l.specReflect + l.specTransmit + l.clearcoat + l.diffuse;
  float r = total > 0.f ? 1.f / total : 0.f;
  l.specReflect *= r;
  l.specTransmit *= r;
  l.clearcoat *= r;
  l.diffuse *= r;
  return l;
}

// Whether sampling chooses between lobes (a pure metal without clearcoat has one).
ENVGI_INLINE bool picksALobe(const PrincipledParams& p) {
  float btdf = glassWeight(p), brdf = baseWeight(p);
  int lobes = int(brdf * p.diffuseRate > 0.f) + int(p.clearcoat * p.clearcoatRate > 0.f) + int(p.specularRate > 0.f);
  return btdf > 0.f || lobes > 1;
}

// Seen from inside, only a transmitting principled BSDF has anything.
ENVGI_INLINE bool hasSide(const PrincipledParams& p, float co) {
  return co > 0.f || (co < 0.f && glassWeight(p) > 0.f);
}

ENVGI_INLINE Color eval(const PrincipledParams& p, Color base, float eta, Vec3f o, Vec3f i) {
  Pair q;
  if (!hasSide(p, o.z) || !pairOf(eta, o, i, &q)) return Color(0.f);
  float brdf = baseWeight(p), btdf = glassWeight(p);
  float co = std::fabs(o.z), ci = std::fabs(i.z);
  MicrofacetDistribution d = specularLobe(p);
  float DG = d.D(q.h) * d.G(o, i);
  float lum = luminance(base);
  Color tint = lum > 0.f ? base / lum : Color(1.f);
  Color v(0.f);
  if (q.specReflect && q.F > 0.f) {
    Color F(btdf * q.F);  // from inside: the glass's Fresnel alone
    if (q.front) {
      // Dielectric, tinted dielectric (Schlick from the tint) and metallic (Schlick from the base).
      float oh = dot(o, q.h), w = interfaceWeight(oh, eta);
      float etaIt = oh >= 0.f ? eta : 1.f / eta, r0 = sqr((etaIt - 1.f) / (etaIt + 1.f));
      F = Color((1.f - p.metallic) * (1.f - p.specTint) * q.F) + schlick(base, w) * p.metallic +
          schlick(tint * r0, w) * ((1.f - p.metallic) * p.specTint);
    }
    v += F * (DG / (4.f * co));
  }
  if (btdf > 0.f && q.specTransmit && q.F < 1.f) {
    float oh = dot(o, q.h), ih = dot(i, q.h);
    Color rootBase(std::sqrt(fmaxf(base.x, 0.f)), std::sqrt(fmaxf(base.y, 0.f)), std::sqrt(fmaxf(base.z, 0.f)));
    // Walter et al. 2007 with radiance's 1/eta^2 compression, as RoughDielectric's.
    v += rootBase * (btdf * std::fabs((1.f - q.F) * DG * oh * ih / (co * sqr(oh + q.etaPath * ih))));
  }
  if (!q.front || !q.reflect) return v;
  if (p.clearcoat > 0.f && q.specReflect) {
    // Mitsuba's clearcoat term: 0.25 F D G |cos i|, without microfacet theory's 1 / (4 cos o cos i).
    float Fcc = 0.04f + 0.96f * interfaceWeight(dot(o, q.h), eta);
    float G = clearcoatG1(o, q.h) * clearcoatG1(i, q.h);
    v += Color(0.25f * p.clearcoat * Fcc * gtr1D(clearcoatAlpha(p), q.h.z) * G * ci);
  }
  if (brdf > 0.f) {
    float Fo = schlickWeight(ci), Fi = schlickWeight(co);  // Mitsuba's names: its wo is our i
    float cosD = dot(q.h, i), Rr = 2.f * p.roughness * cosD * cosD;
    float k = (1.f - 0.5f * Fi) * (1.f - 0.5f * Fo) + Rr * (Fo + Fi + Fo * Fi * (Rr - 1.f));
    if (p.flatness > 0.f) {  // Hanrahan-Krueger's fake subsurface
      float fss90 = 0.5f * Rr, fss = lerpf(Fo, 1.f, fss90) * lerpf(Fi, 1.f, fss90);
      k = lerpf(p.flatness, k, 1.25f * (fss * (1.f / (co + ci) - 0.5f) + 0.5f));
    }
    v += base * (brdf * ci * kInvPi * k);
    if (p.sheen > 0.f && p.metallic < 1.f) {
      Color sheenColor = Color(1.f) * (1.f - p.sheenTint) + tint * p.sheenTint;
      v += sheenColor * (p.sheen * (1.f - p.metallic) * schlickWeight(std::fabs(cosD)) * ci);
    }
  }
  return v;
}

ENVGI_INLINE float pdf(const PrincipledParams& p, float eta, Vec3f o, Vec3f i) {
  Pair q;
  if (!hasSide(p, o.z) || !pairOf(eta, o, i, &q)) return 0.f;
  LobeProbs l = lobeProbs(p, q.front, q.F);
  float ih = dot(i, q.h);
  float dhdi = q.reflect ? 1.f / (4.f * std::fabs(ih)) : std::fabs(q.etaPath * q.etaPath * ih / sqr(dot(o, q.h) + q.etaPath * ih));
  Vec3f up = q.front ? o : -o;
  float visible = q.specReflect || q.specTransmit ? specularLobe(p).visiblePdf(up, q.h) : 0.f;
  float pr = 0.f;
  if (q.specReflect) {
    pr += l.specReflect * visible * dhdi;
    pr += l.clearcoat * q.h.z * gtr1D(clearcoatAlpha(p), q.h.z) * dhdi;
  }
  if (q.specTransmit) pr += l.specTransmit * visible * dhdi;
  if (q.reflect) pr += l.diffuse * cosineHemispherePdf(i.z);
  return pr;
}

// The specular pair's direction about microfacet m (facing +z): refracted through it or
// reflected; false where it falls on the wrong side.
ENVGI_INLINE bool specularDirection(float eta, Vec3f o, Vec3f m, bool transmit, Vec3f* wi) {
  float s = o.z > 0.f ? 1.f : -1.f;
  if (transmit) {
    float c = dot(o, m), e = eta;
    Vec3f n = m;
    if (c < 0.f) {
      e = 1.f / eta;
      n = -m;
    }
    if (!refractDir(o, n, e, wi)) return false;
    return wi->z * o.z < 0.f && dot(o, m) * s > 0.f && dot(*wi, m) * s < 0.f;
  }
  *wi = reflect(o, m);
  return wi->z * o.z > 0.f && dot(o, m) * s > 0.f && dot(*wi, m) * s > 0.f;
}

// Whether sampleDirection(..., lobeFromU = true) still reads uc: to split the specular pair
// between reflection and transmission, which only glass has.
ENVGI_INLINE bool readsUcBesideU(const PrincipledParams& p) { return glassWeight(p) > 0.f; }

// A direction by one lobe, chosen by uc; false where it falls on the wrong side. The caller
// takes its pdf and weight from pdf() and eval() (Bsdf.h's finishSample).
// With lobeFromU, u.x picks among the diffuse, the clearcoat and the specular pair, whose shares
// do not depend on F (lobeProbs), and is stretched over the chosen share; uc then splits the pair
// by F at the microfacet drawn. Each lobe keeps u's stratification, and the density is the same.
ENVGI_INLINE bool sampleDirection(const PrincipledParams& p, float eta, Vec3f o, float uc, Vec2f u, Vec3f* wi,
                                  bool lobeFromU = false) {
  if (!hasSide(p, o.z)) return false;
  if (lobeFromU) {
    const LobeProbs l0 = lobeProbs(p, o.z > 0.f, 0.f);
    const float pd = l0.diffuse, pc = l0.clearcoat;
    if (u.x < pd) {
      *wi = sampleCosineHemisphere(Vec2f(stretchedDraw(u.x, 0.f, pd), u.y));
      return wi->z > 0.f;
    }
    if (u.x < pd + pc) {
      Vec3f mc = gtr1Sample(clearcoatAlpha(p), Vec2f(stretchedDraw(u.x, pd, pc), u.y));
      *wi = reflect(o, mc);
      return wi->z > 0.f && dot(o, mc) > 0.f && dot(*wi, mc) > 0.f;
    }
    if (!(l0.specReflect + l0.specTransmit > 0.f)) return false;
    const float ps = 1.f - pd - pc;
    const Vec3f m = specularLobe(p).sampleVisible(o, Vec2f(stretchedDraw(u.x, pd + pc, ps), u.y));
    const LobeProbs l = lobeProbs(p, o.z > 0.f, fresnelDielectric(dot(o, m), eta));
    const float pair = l.specReflect + l.specTransmit;
    return specularDirection(eta, o, m, pair > 0.f && uc * pair < l.specTransmit, wi);
  }
  MicrofacetDistribution d = specularLobe(p);
  Vec3f m = d.sampleVisible(o, u);  // facing +z
  float F = fresnelDielectric(dot(o, m), eta);
  LobeProbs l = lobeProbs(p, o.z > 0.f, F);
  if (uc < l.diffuse) {
    *wi = sampleCosineHemisphere(u);
    return wi->z > 0.f;
  }
  if (uc < l.diffuse + l.clearcoat) {
    Vec3f mc = gtr1Sample(clearcoatAlpha(p), u);
    *wi = reflect(o, mc);
    return wi->z > 0.f && dot(o, mc) > 0.f && dot(*wi, mc) > 0.f;
  }
  return specularDirection(eta, o, m, uc < l.diffuse + l.clearcoat + l.specTransmit, wi);
}

}  // namespace principled
}  // namespace envgi
