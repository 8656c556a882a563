// Where the parts of a bounce come from. The integrators ask a Parts for each part once: the
// hit's interaction and a blend's other material, where an escaped ray meets the map and the
// radiance there, the bounce's two pairs of draws, the light sample, the BSDF's value in the
// light's direction and the BSDF's sample. SampledParts works each out from the scene and the
// sampler. Another Parts may hand a path parts worked out elsewhere (for many paths at once,
// say), and must give exactly what SampledParts gives, to the bit.
#pragma once

#include "lights/LightSampling.h"
#include "materials/BsdfMix.h"
#include "materials/ShadeKind.h"
#include "sampling/Sampler.h"

namespace envgi {

enum class BouncePair : int { Light, Bsdf };

struct SampledParts {
  const SceneView& sc;

  ENVGI_HD SurfaceInteraction interaction(const Ray& ray, const Hit& h) const { return sc.interaction(ray, h); }
  // A blend's other material at si (textured into *scratch where it has textures), or none.
  ENVGI_HD const Bsdf* partner(const SurfaceInteraction& si, BsdfScratch* scratch) const {
    return sc.partnerAt(si, scratch);
  }
  // Where a ray that escaped meets the map (what eval and evalWithPdf find), and the map's
  // radiance there.
  ENVGI_HD Vec2f mapUV(const Ray& ray) const { return sc.env.uvOf(ray.d); }
  ENVGI_HD Color mapRadiance(Vec2f uv) const { return sc.env.lookupUV(uv); }
  // The pair `which` at the sampler's position.
  ENVGI_HD Vec2f pair(Sampler& smp, BouncePair) const { return smp.get2D(); }
  ENVGI_HD bool lightSample(const SurfaceInteraction& si, Vec3f axis, EnvStrategy strategy, Vec2f u, Vec2f u2,
                            LightSample* ls) const {
    return sampleLight(sc, si, axis, strategy, u, u2, ls);
  }
  // bsdf, beside a blend's partner (or none), at si.partnerWeight: its value for wo and wi in the
  // shading frame, and its density for wi.
  ENVGI_HD Color bsdfValue(const Bsdf& bsdf, const Bsdf* partner, const SurfaceInteraction& si, Vec3f wo, Vec3f wi,
                           float* pdf) const {
    return bsdfMixEvalPdf(bsdf, partner, si.partnerWeight, wo, wi, pdf);
  }
  // Out of line on the GPU, as prepareLd.
  ENVGI_HD_NOINLINE bool bsdfSample(const Bsdf& bsdf, Vec3f wo, float uc, Vec2f u, BsdfSample* bs) const {
    return envgi::bsdfSample(bsdf, wo, uc, u, bs, true);
  }
};

// SampledParts for a hit whose material is of type T and no blend (so it has no partner): the
// BSDF's value and sample then hold type T's code alone, the same to the bit.
template <BsdfType T>
struct TypedParts : SampledParts {
  ENVGI_HD const Bsdf* partner(const SurfaceInteraction&, BsdfScratch*) const { return nullptr; }
  ENVGI_HD Color bsdfValue(const Bsdf& bsdf, const Bsdf*, const SurfaceInteraction&, Vec3f wo, Vec3f wi,
                           float* pdf) const {
    return bsdfEvalPdfAs(bsdf, T, wo, wi, pdf);
  }
  ENVGI_HD_NOINLINE bool bsdfSample(const Bsdf& bsdf, Vec3f wo, float uc, Vec2f u, BsdfSample* bs) const {
    return bsdfSampleAs(bsdf, T, wo, uc, u, bs, true);
  }
};

}  // namespace envgi
