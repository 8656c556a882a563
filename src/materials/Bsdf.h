// The BSDFs of the supported Mitsuba subset as one plain struct with tagged dispatch (no
// virtual calls), usable in CUDA kernels. All directions are in the local shading frame
// (z = shading normal), both pointing away from the surface. As in Mitsuba, eval() returns
// f(wo, wi) |cos theta_i| of the non-delta lobes; delta lobes are reached only by sample().
#pragma once

#include "core/Frame.h"
#include "materials/Fresnel.h"
#include "materials/Microfacet.h"
#include "materials/Principled.h"
#include "materials/RoughCoat.h"
#include "sampling/Warp.h"

namespace envgi {

enum class BsdfType : int {
  Diffuse = 0,
  Conductor,       // smooth; perfectMirror or complex Fresnel
  RoughConductor,  // microfacet (GGX or Beckmann)
  Dielectric,      // smooth glass
  ThinDielectric,  // thin sheet: reflection or straight transmission
  RoughDielectric, // microfacet glass (Walter et al. 2007)
  Plastic,         // smooth dielectric coating over a diffuse base
  RoughPlastic,    // microfacet coating over a diffuse base
  Principled,      // Mitsuba 3's principled (materials/Principled.h)
};

// Roughness bounds: the scene format accepts alpha in (0, 4], and below kMinAlpha microfacet
// sampling is numerically a mirror, so smaller values (given or textured) are raised to it.
constexpr float kMinAlpha = 1e-3f, kMaxAlpha = 4.f;
static_assert(kCoatAlphaMin == kMinAlpha && kCoatAlphaMax == kMaxAlpha, "the coat's tables span the roughness bounds");

struct Bsdf {
  BsdfType type = BsdfType::Diffuse;
  bool twoSided = false;
  bool perfectMirror = false;            // conductor material "none"
  bool nonlinear = false;                // plastics: Mitsuba's `nonlinear`, the base's colour saturates under the coat
  bool flipInvalidNormals = true;        // normalmap (below): Mitsuba's flip_invalid_normals
  bool bumpShadowing = true;             // normalmap: use_shadowing_function, Estevez et al.'s terminator term
  MicrofacetType distribution = MicrofacetType::GGX;  // of the rough BSDFs
  Color reflectance{0.5f};               // diffuse (and plastic base) albedo
  Color specularReflectance{1.f};
  Color specularTransmittance{1.f};
  Color eta{0.f}, k{1.f};                // conductor complex index, per channel
  float alpha = 0.1f;                    // microfacet roughness (along the shading frame's s)
  float alphaV = -1.f;                   // anisotropic: roughness along t (Mitsuba's alpha_v); < 0: alpha
  float ior = 1.5046f;                   // interior / exterior index of refraction
  float fdrInt = 0.f;                    // plastic: diffuse Fresnel reflectance seen from inside
  float fdrExt = 0.f;                    // plastic: the same seen from outside
  float specularSamplingWeight = 0.5f;   // plastic: share of samples given to the coating
  // Textures replacing the values above at a hit (SceneView::bsdfAt); -1: none.
  int reflectanceTexture = -1, specularReflectanceTexture = -1, specularTransmittanceTexture = -1;
  int alphaTexture = -1;   // alpha (alpha_u), read as its luminance, as Mitsuba reads a colour as a float
  int alphaVTexture = -1;  // alphaV (alpha_v), the same way
  // roughplastic: where its coat's tables are (materials/RoughCoat.h; attachRoughCoat fills
  // them, bsdfCoatTable reads them), with coatNodes roughness nodes; none: the smooth coat's
  // Fresnel terms stand in. The address is kept as two halves so that the struct stays 4-byte
  // aligned: a pointer member cost the path kernel 7 registers on sm_90 (96 to 103).
  uint32_t coatTableLo = 0, coatTableHi = 0;
  int coatNodes = 0;
  // Mitsuba's normalmap adapter around this BSDF: a texture of normals relative to the shading
  // frame (rgb = (n + 1) / 2) tilts the frame this BSDF is evaluated in; -1: none. mappedNormal
  // is its unit normal at the hit, which SceneView::bsdfAt fills in (local z where unmapped).
  // Its two flags sit with the other bools above.
  int normalMapTexture = -1;
  Vec3f mappedNormal{0.f, 0.f, 1.f};
  // Mitsuba's bumpmap adapter: a height texture (its luminance) whose (u, v) gradient, times
  // bumpScale, tilts the normal as a displaced surface's would; -1: none. bsdfAt fills in
  // mappedNormal from it; from there on it is a normal map (its two flags included).
  int bumpTexture = -1;
  float bumpScale = 1.f;
  PrincipledParams principled;
  int roughnessTexture = -1, metallicTexture = -1;  // principled: its roughness and metallic, as luminance
  // Mitsuba's mask adapter: the chance that a ray meeting the surface stops there (1: opaque),
  // or a texture whose luminance it is. It is not a lobe: the tracers let a ray through with
  // the chance 1 - opacity (SceneView::stopsAtMask), and where one stops, the BSDF above
  // scatters at full strength.
  float opacity = 1.f;
  int opacityTexture = -1;
  // Mitsuba's blendbsdf: an entry that is no material of its own but a choice between the
  // entries blend0 and blend1, made afresh where each ray meets the surface
  // (SceneView::interaction): blend1 with the chance of blendWeight (a number, or a texture's
  // luminance, clamped to [0, 1] as Mitsuba does), as pbrt-v4's MixMaterial. On average that
  // is Mitsuba's (1 - w) f0 + w f1, and every integrator sees a plain BSDF. -1: no blend.
  int blend0 = -1, blend1 = -1;
  float blendWeight = 0.5f;
  int blendWeightTexture = -1;
};

ENVGI_INLINE const float* bsdfCoatTable(const Bsdf& b) {
  return reinterpret_cast<const float*>((uint64_t(b.coatTableHi) << 32) | uint64_t(b.coatTableLo));
}
ENVGI_INLINE void setBsdfCoatTable(Bsdf& b, const float* table) {
  uint64_t a = uint64_t(reinterpret_cast<uintptr_t>(table));
  b.coatTableLo = uint32_t(a);
  b.coatTableHi = uint32_t(a >> 32);
}

struct BsdfSample {
  Vec3f wi;
  Color weight;      // f |cos| / pdf
  float pdf = 0.f;   // for a delta lobe: the probability of choosing it
  bool delta = false;
};

// The squared relative index of refraction a path crossed going from wo to wi through a
// dielectric (1 for reflection and for thin sheets): the 1/eta^2 by which radiance was
// compressed, which Russian roulette should not count as lost throughput (pbrt-v4's etaScale,
// Mitsuba 3's eta^2 in its roulette).
namespace detail {
ENVGI_INLINE float etaSquaredInFrame(const Bsdf& b, Vec3f wo, Vec3f wi) {
  if ((b.type != BsdfType::Dielectric && b.type != BsdfType::RoughDielectric && b.type != BsdfType::Principled) ||
      wo.z * wi.z >= 0.f)
    return 1.f;
  float etap = wo.z > 0.f ? b.ior : 1.f / b.ior;
  return etap * etap;
}
}  // namespace detail

ENVGI_INLINE bool bsdfIsAnisotropic(const Bsdf& b) { return b.alphaV >= 0.f; }
ENVGI_INLINE MicrofacetDistribution microfacet(const Bsdf& b) {
  return {b.alpha, bsdfIsAnisotropic(b) ? b.alphaV : b.alpha, b.distribution};
}

ENVGI_INLINE bool bsdfIsNormalMapped(const Bsdf& b) { return b.normalMapTexture >= 0 || b.bumpTexture >= 0; }
// Hits on this material build their shading frame along dp/du (Mitsuba's): an anisotropic
// lobe is oriented by it, and a normal map's tangent space is that frame.
ENVGI_INLINE bool bsdfNeedsTangentFrame(const Bsdf& b) {
  return bsdfIsAnisotropic(b) || bsdfIsNormalMapped(b) || (b.type == BsdfType::Principled && b.principled.anisotropic != 0.f);
}

ENVGI_INLINE bool bsdfIsMasked(const Bsdf& b) { return b.opacityTexture >= 0 || b.opacity < 1.f; }
ENVGI_INLINE bool bsdfIsBlend(const Bsdf& b) { return b.blend0 >= 0; }
// How deep blends may nest (the loader's limit, which bounds the choice's loop on the device).
constexpr int kMaxBlendDepth = 8;

ENVGI_INLINE bool bsdfHasTexture(const Bsdf& b) {
  return b.reflectanceTexture >= 0 || b.specularReflectanceTexture >= 0 || b.specularTransmittanceTexture >= 0 ||
         b.alphaTexture >= 0 || b.alphaVTexture >= 0 || b.normalMapTexture >= 0 || b.roughnessTexture >= 0 ||
         b.metallicTexture >= 0 || b.bumpTexture >= 0;
}

// True when every lobe is a delta: next-event estimation is pointless there.
ENVGI_INLINE bool bsdfIsDelta(const Bsdf& b) {
  return b.type == BsdfType::Conductor || b.type == BsdfType::Dielectric || b.type == BsdfType::ThinDielectric;
}
ENVGI_INLINE bool bsdfTransmits(const Bsdf& b) {
  return b.type == BsdfType::Dielectric || b.type == BsdfType::ThinDielectric || b.type == BsdfType::RoughDielectric ||
         (b.type == BsdfType::Principled && b.principled.specTrans > 0.f);
}

namespace detail {

ENVGI_INLINE float plasticSpecularProb(const Bsdf& b, float fo) {
  float ps = fo * b.specularSamplingWeight, pd = (1.f - fo) * (1.f - b.specularSamplingWeight);
  return ps + pd > 0.f ? ps / (ps + pd) : 0.f;
}

// The base's albedo after its inter-reflections under a coat whose internal diffuse reflectance
// is fdrInt, times num / ior^2: Mitsuba's linear form divides by 1 - Fdr_int alone; its
// nonlinear one by 1 - albedo Fdr_int, per channel, so that a coloured base saturates.
ENVGI_INLINE Color plasticBase(const Bsdf& b, float fdrInt, float num) {
  if (!b.nonlinear) return b.reflectance * (num / ((1.f - fdrInt) * b.ior * b.ior));
  const Color& r = b.reflectance;
  return Color(r.x / (1.f - r.x * fdrInt), r.y / (1.f - r.y * fdrInt), r.z / (1.f - r.z * fdrInt)) *
         (num / (b.ior * b.ior));
}

// Diffuse base under a coating (Mitsuba's plastic); fo is the Fresnel reflectance at wo, which
// the plastics' pdfs need too.
ENVGI_INLINE Color plasticDiffuse(const Bsdf& b, float fo, Vec3f wi) {
  float ti = 1.f - fresnelDielectric(wi.z, b.ior), to = 1.f - fo;
  return plasticBase(b, b.fdrInt, kInvPi * wi.z * ti * to);
}
ENVGI_INLINE Color plasticDiffuse(const Bsdf& b, Vec3f wo, Vec3f wi) {
  return plasticDiffuse(b, fresnelDielectric(wo.z, b.ior), wi);
}

// Rough dielectric: generalised half vector and the relative index along wo.
ENVGI_INLINE bool roughDielectricHalf(const Bsdf& b, Vec3f wo, Vec3f wi, Vec3f* wm, float* etap) {
  float co = wo.z, ci = wi.z;
  if (co == 0.f || ci == 0.f) return false;
  bool reflect = co * ci > 0.f;
  *etap = reflect ? 1.f : (co > 0.f ? b.ior : 1.f / b.ior);
  Vec3f m = wi * (*etap) + wo;
  if (lengthSq(m) == 0.f) return false;
  m = normalize(m);
  if (m.z < 0.f) m = -m;
  // Microfacets seen from behind contribute nothing.
  if (dot(m, wi) * ci < 0.f || dot(m, wo) * co < 0.f) return false;
  *wm = m;
  return true;
}

// A two-sided BSDF seen from behind is the front side mirrored through the surface.
ENVGI_INLINE void toFrontSide(const Bsdf& b, Vec3f* wo, Vec3f* wi) {
  if (b.twoSided && wo->z < 0.f) {
    wo->z = -wo->z;
    wi->z = -wi->z;
  }
}

// The rough coat's tables at this material's roughness (Mitsuba's roughplastic).
ENVGI_INLINE CoatNode roughCoat(const Bsdf& b) { return coatNode(bsdfCoatTable(b), b.coatNodes, b.alpha); }

// The share of light from wo (cos theta = c > 0) that the rough coat (n: roughCoat(b)) does not
// let through to the base: the coat's lobe's share in sampling. The smooth coat's Fresnel
// without tables.
ENVGI_INLINE float roughCoatReflectanceAt(const CoatNode& n, CoatPlace p) { return 1.f - coatTransmittanceAt(n, p); }
ENVGI_INLINE float roughCoatReflectance(const Bsdf& b, const CoatNode& n, float c) {
  return b.coatNodes > 0 ? roughCoatReflectanceAt(n, coatPlace(c)) : fresnelDielectric(c, b.ior);
}

// What rough plastic's eval and pdf share for one pair of directions (both above the surface):
// the half vector, D there, wo's Smith lambda, the coat's tables at this roughness and its
// reflectance at wo. bsdfEvalPdf computes them once for both.
// d and coat: microfacet(b) and roughCoat(b), which a batch of one material works out once.
struct RoughPlasticShared {
  Vec3f m;
  float D, lambdaO, fo;
  CoatNode coat;
};
ENVGI_INLINE RoughPlasticShared roughPlasticShared(const MicrofacetDistribution& d, const CoatNode& coat, float fo,
                                                   Vec3f wo, Vec3f wi) {
  RoughPlasticShared r;
  r.m = normalize(wo + wi);
  r.D = d.D(r.m);
  r.lambdaO = d.lambda(wo);
  r.coat = coat;
  r.fo = fo;
  return r;
}
ENVGI_INLINE RoughPlasticShared roughPlasticShared(const Bsdf& b, Vec3f wo, Vec3f wi) {
  const CoatNode coat = roughCoat(b);
  return roughPlasticShared(microfacet(b), coat, roughCoatReflectance(b, coat, wo.z), wo, wi);
}
// The base seen through the rough coat with its tables: t(wi) t(wo) times plasticBase with the
// rough Fdr_int; ti is t(wi).
ENVGI_INLINE Color roughPlasticThroughCoat(const Bsdf& b, const RoughPlasticShared& r, float ti, Vec3f wi) {
  float to = 1.f - r.fo;
  return plasticBase(b, coatInternalReflectance(r.coat), kInvPi * wi.z * ti * to);
}
ENVGI_INLINE Color roughPlasticDiffuse(const Bsdf& b, const RoughPlasticShared& r, Vec3f wi) {
  if (b.coatNodes == 0) return plasticDiffuse(b, r.fo, wi);
  return roughPlasticThroughCoat(b, r, coatTransmittance(r.coat, wi.z), wi);
}
// The coat's own lobe: a microfacet reflection, with the height-correlated masking of G().
ENVGI_INLINE Color roughPlasticSpecular(const Bsdf& b, const MicrofacetDistribution& d, const RoughPlasticShared& r,
                                        Vec3f wo, Vec3f wi) {
  float F = fresnelDielectric(dot(wi, r.m), b.ior);
  float G = 1.f / (1.f + r.lambdaO + d.lambda(wi));
  return b.specularReflectance * (F * r.D * G / (4.f * wo.z));
}
ENVGI_INLINE Color roughPlasticEval(const Bsdf& b, const MicrofacetDistribution& d, const RoughPlasticShared& r,
                                    Vec3f wo, Vec3f wi) {
  return roughPlasticSpecular(b, d, r, wo, wi) + roughPlasticDiffuse(b, r, wi);
}
ENVGI_INLINE float roughPlasticPdf(const Bsdf& b, const RoughPlasticShared& r, Vec3f wo, Vec3f wi) {
  float ps = plasticSpecularProb(b, r.fo);
  // visiblePdf(wo, m), with G1(wo) = 1 / (1 + lambda(wo)), over the half vector's Jacobian
  // 4 |wo.m|; wo.z > 0 here, so |wo.z| is wo.z.
  float cosOM = std::fabs(dot(wo, r.m));
  float visible = 1.f / (1.f + r.lambdaO) * cosOM * r.D / wo.z;
  return ps * (visible / (4.f * cosOM)) + (1.f - ps) * cosineHemispherePdf(wi.z);
}
// evalPdfInFrame's rough plastic with its coat's tables, for directions above the surface, its
// two table lookups given (fo: roughCoatReflectanceAt at wo, ti: t(wi)): the value, and the
// density in *pdf. Apart, so that a batch of lookups can be made first.
ENVGI_INLINE Color roughPlasticTabledEvalPdf(const Bsdf& b, const MicrofacetDistribution& d, const CoatNode& coat,
                                             float fo, float ti, Vec3f wo, Vec3f wi, float* pdf) {
  const RoughPlasticShared r = roughPlasticShared(d, coat, fo, wo, wi);
  *pdf = roughPlasticPdf(b, r, wo, wi);
  return roughPlasticSpecular(b, d, r, wo, wi) + roughPlasticThroughCoat(b, r, ti, wi);
}

// Rough plastic's sample with the lobe from u.x (bsdfLobeFromU, as path and direct draw it) in
// the steps of sampleInFrame's that a batch of samples can run in vector lanes around
// libm's sine and cosine (fromPolar), one lane at a time: the lobe's draw (plasticLobeDraw),
// its disk point in polar form, the direction from the point, then roughPlasticTabledEvalPdf.
// wo is above the surface (a two-sided one's seen from the front); d: microfacet(b), GGX's.

// ps: the coat's share of the samples from wo (plasticSpecularProb); u.x < ps picks the coat,
// and u.x is then stretched over the lobe's share, in one stretchedDraw call (a choice between
// two calls' clamps became a choice between masks, which GCC does not vectorise). Both plastics.
ENVGI_INLINE float plasticLobeDraw(float ps, float ux) {
  const bool coatLobe = ux < ps;
  return stretchedDraw(ux, coatLobe ? 0.f : ps, coatLobe ? ps : 1.f - ps);
}
// u: the draw with u.x stretched (plasticLobeDraw): the lobe's disk point in polar form.
ENVGI_INLINE PolarPoint roughPlasticDisk(bool coatLobe, Vec2f u) {
  const PolarPoint visible = MicrofacetDistribution::visibleDiskPolar(u), base = concentricDiskPolar(u);
  return {coatLobe ? visible.r : base.r, coatLobe ? visible.angle : base.angle};
}
ENVGI_INLINE Vec3f roughPlasticDirection(const MicrofacetDistribution& d, Vec3f wo, Vec2f disk, bool coatLobe) {
  return coatLobe ? reflect(wo, d.visibleGgxFromDisk(wo, disk)) : cosineHemisphereFromDisk(disk);
}
}  // namespace detail

// The dispatch over the types reads `type`, which is b.type: a caller that knows b's type gives
// it as a constant, and the compiler keeps that type's code alone (materials/ShadeKind.h).
namespace detail {
ENVGI_INLINE Color evalInFrame(const Bsdf& b, BsdfType type, Vec3f wo, Vec3f wi) {
  detail::toFrontSide(b, &wo, &wi);
  switch (type) {
    case BsdfType::Diffuse:
      if (wo.z <= 0.f || wi.z <= 0.f) return Color(0.f);
      return b.reflectance * (kInvPi * wi.z);
    case BsdfType::RoughConductor: {
      if (wo.z <= 0.f || wi.z <= 0.f) return Color(0.f);
      Vec3f m = normalize(wo + wi);
      MicrofacetDistribution d = microfacet(b);
      Color F = b.perfectMirror ? Color(1.f) : fresnelConductor(dot(wi, m), b.eta, b.k);
      return b.specularReflectance * F * (d.D(m) * d.G(wo, wi) / (4.f * wo.z));
    }
    case BsdfType::RoughDielectric: {
      Vec3f m;
      float etap;
      if (!detail::roughDielectricHalf(b, wo, wi, &m, &etap)) return Color(0.f);
      MicrofacetDistribution d = microfacet(b);
      float F = fresnelDielectric(dot(wo, m), b.ior);
      float co = std::fabs(wo.z);
      if (wo.z * wi.z > 0.f) return b.specularReflectance * (d.D(m) * d.G(wo, wi) * F / (4.f * co));
      float denom = sqr(dot(wi, m) + dot(wo, m) / etap) * co;
      float ft = d.D(m) * (1.f - F) * d.G(wo, wi) * std::fabs(dot(wi, m) * dot(wo, m) / denom);
      return b.specularTransmittance * (ft / (etap * etap));  // radiance is compressed by 1/eta^2
    }
    case BsdfType::Plastic:
      if (wo.z <= 0.f || wi.z <= 0.f) return Color(0.f);
      return detail::plasticDiffuse(b, wo, wi);
    case BsdfType::RoughPlastic:
      if (wo.z <= 0.f || wi.z <= 0.f) return Color(0.f);
      return detail::roughPlasticEval(b, microfacet(b), detail::roughPlasticShared(b, wo, wi), wo, wi);
    case BsdfType::Principled: return principled::eval(b.principled, b.reflectance, b.ior, wo, wi);
    case BsdfType::Conductor:
    case BsdfType::Dielectric:
    case BsdfType::ThinDielectric:
      break;  // pure delta lobes
  }
  return Color(0.f);
}

ENVGI_INLINE float pdfInFrame(const Bsdf& b, BsdfType type, Vec3f wo, Vec3f wi) {
  detail::toFrontSide(b, &wo, &wi);
  switch (type) {
    case BsdfType::Diffuse:
      if (wo.z <= 0.f || wi.z <= 0.f) return 0.f;
      return cosineHemispherePdf(wi.z);
    case BsdfType::RoughConductor: {
      if (wo.z <= 0.f || wi.z <= 0.f) return 0.f;
      Vec3f m = normalize(wo + wi);
      return microfacet(b).visiblePdf(wo, m) / (4.f * std::fabs(dot(wo, m)));
    }
    case BsdfType::RoughDielectric: {
      Vec3f m;
      float etap;
      if (!detail::roughDielectricHalf(b, wo, wi, &m, &etap)) return 0.f;
      MicrofacetDistribution d = microfacet(b);
      float R = fresnelDielectric(dot(wo, m), b.ior), T = 1.f - R;
      if (wo.z * wi.z > 0.f) return d.visiblePdf(wo, m) / (4.f * std::fabs(dot(wo, m))) * R;
      float dwmdwi = std::fabs(dot(wi, m)) / sqr(dot(wi, m) + dot(wo, m) / etap);
      return d.visiblePdf(wo, m) * dwmdwi * T;
    }
    case BsdfType::Plastic: {
      if (wo.z <= 0.f || wi.z <= 0.f) return 0.f;
      float ps = detail::plasticSpecularProb(b, fresnelDielectric(wo.z, b.ior));
      return (1.f - ps) * cosineHemispherePdf(wi.z);
    }
    case BsdfType::RoughPlastic:
      if (wo.z <= 0.f || wi.z <= 0.f) return 0.f;
      return detail::roughPlasticPdf(b, detail::roughPlasticShared(b, wo, wi), wo, wi);
    case BsdfType::Principled: return principled::pdf(b.principled, b.ior, wo, wi);
    case BsdfType::Conductor:
    case BsdfType::Dielectric:
    case BsdfType::ThinDielectric:
      break;  // pure delta lobes
  }
  return 0.f;
}

// bsdfEval and bsdfPdf of one pair of directions, with the very values of the two calls apart.
// Next-event estimation and BSDF sampling both want both (Mitsuba's eval_pdf); rough plastic,
// the example scenes' glossy BSDF, then computes what the two share once instead of twice.
// Rough conductor's value and density for wo and wi above the (front) surface: evalInFrame's and
// pdfInFrame's, to the bit, from one half vector. Apart, for a batch of one material.
ENVGI_INLINE Color roughConductorEvalPdf(const Bsdf& b, const MicrofacetDistribution& d, Vec3f wo, Vec3f wi,
                                         float* pdf) {
  const Vec3f m = normalize(wo + wi);
  *pdf = d.visiblePdf(wo, m) / (4.f * std::fabs(dot(wo, m)));
  const Color F = b.perfectMirror ? Color(1.f) : fresnelConductor(dot(wi, m), b.eta, b.k);
  return b.specularReflectance * F * (d.D(m) * d.G(wo, wi) / (4.f * wo.z));
}

ENVGI_INLINE Color evalPdfInFrame(const Bsdf& b, BsdfType type, Vec3f wo, Vec3f wi, float* pdf) {
  if (type != BsdfType::RoughPlastic) {
    *pdf = pdfInFrame(b, type, wo, wi);
    return evalInFrame(b, type, wo, wi);
  }
  detail::toFrontSide(b, &wo, &wi);
  if (wo.z <= 0.f || wi.z <= 0.f) {
    *pdf = 0.f;
    return Color(0.f);
  }
  detail::RoughPlasticShared r = detail::roughPlasticShared(b, wo, wi);
  *pdf = detail::roughPlasticPdf(b, r, wo, wi);
  return detail::roughPlasticEval(b, microfacet(b), r, wo, wi);
}

// Non-delta lobes: the pdf of the sampled direction over all lobes, and weight = eval / pdf.
ENVGI_INLINE bool finishSample(const Bsdf& b, BsdfType type, Vec3f wo, BsdfSample* s) {
  Color f = evalPdfInFrame(b, type, wo, s->wi, &s->pdf);
  if (!(s->pdf > 0.f)) return false;
  s->weight = f / s->pdf;
  return true;
}
}  // namespace detail

// Whether bsdfSample reads its uc, the choice between lobes (reflection or transmission, coat or
// base); a diffuse or metal BSDF has one lobe, and its draw can be skipped.
ENVGI_INLINE bool bsdfPicksALobe(const Bsdf& b) {
  if (b.type == BsdfType::Principled) return principled::picksALobe(b.principled);
  return b.type != BsdfType::Diffuse && b.type != BsdfType::Conductor && b.type != BsdfType::RoughConductor;
}

// Whether bsdfSample(..., lobeFromU = true) picks the lobe by u.x instead of uc: the lobe by where
// u.x falls among the lobes' shares, then u.x stretched over the chosen share (stretchedDraw).
// A 2D low-discrepancy u then stays stratified within each lobe, where a separate uc splits it
// into unstratified subsets. Plastics, whose shares follow from wo alone, and the principled
// BSDF, whose diffuse, clearcoat and specular pair do; not a rough dielectric, whose reflection
// and transmission shares follow from the microfacet that u itself draws (so does the principled
// BSDF's split of its specular pair, which still reads uc).
ENVGI_INLINE bool bsdfLobeFromU(const Bsdf& b) {
  return b.type == BsdfType::Plastic || b.type == BsdfType::RoughPlastic || b.type == BsdfType::Principled;
}
// Whether bsdfSample reads uc when the caller asks for the lobe from u where it can.
ENVGI_INLINE bool bsdfReadsUcBesideU(const Bsdf& b) {
  if (b.type == BsdfType::Principled) return principled::readsUcBesideU(b.principled);
  return bsdfPicksALobe(b) && !bsdfLobeFromU(b);
}

namespace detail {
// The sampling of the types with several lobes or a refraction, each apart: sampleInFrame's.
// A smooth interface's mirror lobe, drawn with probability R.
ENVGI_INLINE bool sampleSmoothReflection(const Bsdf& b, Vec3f wo, float R, BsdfSample* s) {
  s->wi = Vec3f(-wo.x, -wo.y, wo.z);
  s->pdf = R;
  s->weight = b.specularReflectance;
  s->delta = true;
  return true;
}
ENVGI_INLINE bool sampleDielectric(const Bsdf& b, Vec3f wo, float uc, BsdfSample* s) {
  float R = fresnelDielectric(wo.z, b.ior), T = 1.f - R;
  if (uc < R) return sampleSmoothReflection(b, wo, R, s);
  float etap = wo.z > 0.f ? b.ior : 1.f / b.ior;
  Vec3f n = wo.z > 0.f ? Vec3f(0.f, 0.f, 1.f) : Vec3f(0.f, 0.f, -1.f);
  if (!refractDir(wo, n, etap, &s->wi)) return false;
  s->pdf = T;
  s->weight = b.specularTransmittance / (etap * etap);
  s->delta = true;
  return true;
}
ENVGI_INLINE bool sampleThinDielectric(const Bsdf& b, Vec3f wo, float uc, BsdfSample* s) {
  float R = fresnelDielectric(std::fabs(wo.z), b.ior), T = 1.f - R;
  if (R < 1.f) {  // inter-reflections inside the sheet
    R += T * T * R / (1.f - R * R);
    T = 1.f - R;
  }
  if (uc < R) return sampleSmoothReflection(b, wo, R, s);
  s->wi = -wo;
  s->pdf = T;
  s->weight = b.specularTransmittance;
  s->delta = true;
  return true;
}
ENVGI_INLINE bool sampleRoughDielectric(const Bsdf& b, Vec3f wo, float uc, Vec2f u, BsdfSample* s) {
  if (wo.z == 0.f) return false;
  MicrofacetDistribution d = microfacet(b);
  Vec3f m = d.sampleVisible(wo, u);
  float R = fresnelDielectric(dot(wo, m), b.ior);
  if (uc < R) {
    s->wi = reflect(wo, m);
    if (s->wi.z * wo.z <= 0.f) return false;
  } else {
    float c = dot(wo, m), e = b.ior;
    Vec3f n = m;
    if (c < 0.f) {
      e = 1.f / b.ior;
      n = -m;
    }
    if (!refractDir(wo, n, e, &s->wi) || s->wi.z * wo.z >= 0.f) return false;
  }
  return finishSample(b, BsdfType::RoughDielectric, wo, s);
}
// Plastic and rough plastic: the coat (a mirror, or rough) or the diffuse base, by the coat's
// sampling probability.
ENVGI_INLINE bool samplePlastic(const Bsdf& b, BsdfType type, Vec3f wo, float uc, Vec2f u, BsdfSample* s,
                                bool lobeFromU) {
  if (wo.z <= 0.f) return false;
  float fo = type == BsdfType::Plastic ? fresnelDielectric(wo.z, b.ior)
                                         : detail::roughCoatReflectance(b, detail::roughCoat(b), wo.z);
  float ps = detail::plasticSpecularProb(b, fo);
  if (lobeFromU) {  // bsdfLobeFromU: the coat below ps, the base above
    uc = u.x;
    u.x = plasticLobeDraw(ps, u.x);
  }
  if (type == BsdfType::Plastic && uc < ps) {
    s->wi = Vec3f(-wo.x, -wo.y, wo.z);
    s->pdf = ps;
    s->delta = true;
    s->weight = b.specularReflectance * (fo / ps);
    return true;
  }
  if (type == BsdfType::RoughPlastic && uc < ps) {
    s->wi = reflect(wo, microfacet(b).sampleVisible(wo, u));
  } else {
    s->wi = sampleCosineHemisphere(u);
  }
  if (s->wi.z <= 0.f) return false;
  return finishSample(b, type, wo, s);
}

ENVGI_INLINE bool sampleInFrame(const Bsdf& b, BsdfType type, Vec3f wo, float uc, Vec2f u, BsdfSample* s,
                                bool lobeFromU) {
  bool flip = b.twoSided && wo.z < 0.f;
  if (flip) wo.z = -wo.z;
  bool ok = false;
  s->delta = false;
  switch (type) {
    case BsdfType::Diffuse: {
      if (wo.z <= 0.f) return false;
      s->wi = sampleCosineHemisphere(u);
      s->pdf = cosineHemispherePdf(s->wi.z);
      s->weight = b.reflectance;
      ok = s->pdf > 0.f;
      break;
    }
    case BsdfType::Conductor: {
      if (wo.z <= 0.f) return false;
      s->wi = Vec3f(-wo.x, -wo.y, wo.z);
      s->pdf = 1.f;
      s->delta = true;
      s->weight = b.specularReflectance * (b.perfectMirror ? Color(1.f) : fresnelConductor(wo.z, b.eta, b.k));
      ok = true;
      break;
    }
    case BsdfType::RoughConductor: {
      if (wo.z <= 0.f) return false;
      Vec3f m = microfacet(b).sampleVisible(wo, u);
      s->wi = reflect(wo, m);
      if (s->wi.z <= 0.f) return false;
      ok = detail::finishSample(b, type, wo, s);
      break;
    }
    case BsdfType::Dielectric: ok = sampleDielectric(b, wo, uc, s); break;
    case BsdfType::ThinDielectric: ok = sampleThinDielectric(b, wo, uc, s); break;
    case BsdfType::RoughDielectric: ok = sampleRoughDielectric(b, wo, uc, u, s); break;
    case BsdfType::Plastic:
    case BsdfType::RoughPlastic: ok = samplePlastic(b, type, wo, uc, u, s, lobeFromU); break;
    case BsdfType::Principled:
      if (!principled::sampleDirection(b.principled, b.ior, wo, uc, u, &s->wi, lobeFromU)) return false;
      ok = detail::finishSample(b, type, wo, s);
      break;
  }
  if (ok && flip) s->wi.z = -s->wi.z;
  return ok && isFiniteVec(s->weight);
}
}  // namespace detail

// Probability that bsdfSample picks a delta lobe from wo when the BSDF also has a smooth one
// (smooth plastic's coat); 0 for BSDFs without delta lobes, 1 for purely delta ones. Callers
// that follow delta lobes themselves (SPPM, the photon integrator) split on it.
namespace detail {
ENVGI_INLINE float deltaProbInFrame(const Bsdf& b, Vec3f wo) {
  if (bsdfIsDelta(b)) return 1.f;
  if (b.type != BsdfType::Plastic) return 0.f;
  float c = b.twoSided ? std::fabs(wo.z) : wo.z;
  if (c <= 0.f) return 0.f;
  return detail::plasticSpecularProb(b, fresnelDielectric(c, b.ior));
}
}  // namespace detail

// --- The BSDF as the integrators see it: wo and wi in the hit's shading frame. Without a
// normal map these are the functions above; with one, Mitsuba's normalmap adapter
// (src/bsdfs/normalmap.cpp): directions go into the tilted frame, a direction on different
// sides of the two frames gets nothing, and the shadowing term scales the value.

namespace detail {
// The normal map's frame as seen from wo: with flip_invalid_normals, a normal that wo sees from
// the other side than the unmapped frame's is mirrored about z (Schuessler et al. 2017, as
// Mitsuba does); s is local x made orthogonal to it.
ENVGI_INLINE Frame mappedFrame(const Bsdf& b, Vec3f wo) {
  Vec3f n = b.mappedNormal;
  if (b.flipInvalidNormals && wo.z * dot(wo, n) <= 0.f) n = Vec3f(-n.x, -n.y, n.z);
  return Frame::fromNormalAndTangent(n, Vec3f(1.f, 0.f, 0.f));
}
// Estevez et al. 2019 ("A microfacet-based shadowing function to solve the bump terminator
// problem"): a Smith-like term from the tilt of the mapped normal n, for the light direction wi
// (both in the unmapped frame), which softens the hard edge where a tilted normal's light ends.
ENVGI_INLINE float bumpShadowingTerm(Vec3f n, Vec3f wi) {
  auto tan2 = [](Vec3f v) { return fmaxf(0.f, 1.f - v.z * v.z) / (v.z * v.z); };
  float alpha2 = fminf(0.125f * tan2(n), 1.f);
  return 2.f / (1.f + std::sqrt(1.f + alpha2 * tan2(wi)));
}

}  // namespace detail

ENVGI_INLINE Color bsdfEval(const Bsdf& b, Vec3f wo, Vec3f wi) {
  if (!bsdfIsNormalMapped(b)) return detail::evalInFrame(b, b.type, wo, wi);
  Frame f = detail::mappedFrame(b, wo);
  Vec3f mi = f.toLocal(wi);
  if (!(wi.z * mi.z > 0.f)) return Color(0.f);
  Color v = detail::evalInFrame(b, b.type, f.toLocal(wo), mi);
  return b.bumpShadowing ? v * detail::bumpShadowingTerm(f.n, wi) : v;
}

ENVGI_INLINE float bsdfPdf(const Bsdf& b, Vec3f wo, Vec3f wi) {
  if (!bsdfIsNormalMapped(b)) return detail::pdfInFrame(b, b.type, wo, wi);
  Frame f = detail::mappedFrame(b, wo);
  Vec3f mi = f.toLocal(wi);
  return wi.z * mi.z > 0.f ? detail::pdfInFrame(b, b.type, f.toLocal(wo), mi) : 0.f;
}

// Both at once, as evalPdfInFrame; of a BSDF whose type is `type` (b.type, which a caller may
// know as a constant).
ENVGI_INLINE Color bsdfEvalPdfAs(const Bsdf& b, BsdfType type, Vec3f wo, Vec3f wi, float* pdf) {
  if (!bsdfIsNormalMapped(b)) return detail::evalPdfInFrame(b, type, wo, wi, pdf);
  Frame f = detail::mappedFrame(b, wo);
  Vec3f mi = f.toLocal(wi);
  if (!(wi.z * mi.z > 0.f)) {
    *pdf = 0.f;
    return Color(0.f);
  }
  Color v = detail::evalPdfInFrame(b, type, f.toLocal(wo), mi, pdf);
  return b.bumpShadowing ? v * detail::bumpShadowingTerm(f.n, wi) : v;
}
ENVGI_INLINE Color bsdfEvalPdf(const Bsdf& b, Vec3f wo, Vec3f wi, float* pdf) {
  return bsdfEvalPdfAs(b, b.type, wo, wi, pdf);
}

// uc picks a lobe, u the direction within it; with lobeFromU, u.x picks the lobe where
// bsdfLobeFromU says it can, and uc goes unread there. Returns false when no direction is
// produced. bsdfSampleAs: of a BSDF whose type is `type`, as bsdfEvalPdfAs.
ENVGI_INLINE bool bsdfSampleAs(const Bsdf& b, BsdfType type, Vec3f wo, float uc, Vec2f u, BsdfSample* s,
                               bool lobeFromU = false) {
  if (!bsdfIsNormalMapped(b)) return detail::sampleInFrame(b, type, wo, uc, u, s, lobeFromU);
  Frame f = detail::mappedFrame(b, wo);
  if (!detail::sampleInFrame(b, type, f.toLocal(wo), uc, u, s, lobeFromU)) return false;
  Vec3f mi = s->wi;
  s->wi = f.toWorld(mi);
  if (!(s->wi.z * mi.z > 0.f)) return false;
  if (b.bumpShadowing) s->weight *= detail::bumpShadowingTerm(f.n, s->wi);
  return true;
}
ENVGI_INLINE bool bsdfSample(const Bsdf& b, Vec3f wo, float uc, Vec2f u, BsdfSample* s, bool lobeFromU = false) {
  return bsdfSampleAs(b, b.type, wo, uc, u, s, lobeFromU);
}

ENVGI_INLINE float bsdfEtaSquared(const Bsdf& b, Vec3f wo, Vec3f wi) {
  if (!bsdfIsNormalMapped(b) || !bsdfTransmits(b)) return detail::etaSquaredInFrame(b, wo, wi);
  Frame f = detail::mappedFrame(b, wo);
  return detail::etaSquaredInFrame(b, f.toLocal(wo), f.toLocal(wi));
}

ENVGI_INLINE float bsdfDeltaProb(const Bsdf& b, Vec3f wo) {
  if (!bsdfIsNormalMapped(b) || b.type != BsdfType::Plastic) return detail::deltaProbInFrame(b, wo);
  return detail::deltaProbInFrame(b, detail::mappedFrame(b, wo).toLocal(wo));
}

}  // namespace envgi
