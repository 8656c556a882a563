// What the CPU's batch forms of the wave stages work out for a queue's paths before shading them
// (HostStages.h), and the Parts (integrators/BounceParts.h) that hands each
// path its own when pathShade asks: the parts are SampledParts' to the bit, so the images are
// renderPixel's.
#pragma once

#include "integrators/PathIntegrator.h"
#include "materials/BsdfLanes.h"

namespace envgi {

// A product draw taken a level at a time across the round (ProductDescent), to its end.
struct DescendedDraw {
  bool ended = false;  // u and nLocal name the draw, drawn says whether it drew a pixel
  Vec2f u;
  Vec3f nLocal;
  bool drawn = false;
  Vec2f uv;           // CosineProductView::sample's uv and density, or, once placed, placeInPixel's
  float pdfUV = 0.f;
  bool placed = false;  // placed in lanes, with the direction and the map's radiance there
  Vec3f dir;
  Color radiance;
};

struct PreparedHit {
  SurfaceInteraction si;
  // The light's and the BSDF's pairs (bounceLayout's), where they were drawn for the round.
  bool lightDrawn = false, bsdfDrawn = false;
  Vec2f uL, ub;
  // The BSDF's sample for ub, and its value and density in the light's direction, where a
  // material's lanes made them.
  bool sampled = false, sampleTaken = false;
  BsdfSample sample;
  bool valued = false;
  BsdfEvaluation value;
  DescendedDraw product;
};

struct PreparedParts {
  const SceneView& sc;
  const PreparedHit& hit;

  SurfaceInteraction interaction(const Ray&, const Hit&) const { return hit.si; }
  const Bsdf* partner(const SurfaceInteraction& si, BsdfScratch* scratch) const { return sc.partnerAt(si, scratch); }
  Vec2f mapUV(const Ray& ray) const { return sc.env.uvOf(ray.d); }
  Color mapRadiance(Vec2f uv) const { return sc.env.lookupUV(uv); }
  Vec2f pair(Sampler& smp, BouncePair which) const {
    const bool drawn = which == BouncePair::Light ? hit.lightDrawn : hit.bsdfDrawn;
    if (!drawn) return smp.get2D();
    smp.skip2D();
    return which == BouncePair::Light ? hit.uL : hit.ub;
  }
  bool lightSample(const SurfaceInteraction& si, Vec3f axis, EnvStrategy strategy, Vec2f u, Vec2f u2,
                   LightSample* ls) const {
    const DescendedDraw& d = hit.product;
    Vec2f um = u;
    if (d.ended && lightDrawPicksMap(sc, strategy, &um) &&
        sc.env.strategyFor(strategy, axis) == EnvStrategy::Product && um.x == d.u.x && um.y == d.u.y &&
        sameBits(sc.env.toLocalUnnormalized(axis), d.nLocal)) {
      if (!d.drawn) return false;
      const EnvSample es = d.placed ? sc.env.placedProductSample(d.uv, d.pdfUV, d.dir, d.radiance)
                                    : sc.env.productSample(d.uv, d.pdfUV);
      return mapLightSample(sc, es, ls);
    }
    return sampleLight(sc, si, axis, strategy, u, u2, ls);
  }
  Color bsdfValue(const Bsdf& bsdf, const Bsdf* partner, const SurfaceInteraction& si, Vec3f wo, Vec3f wi,
                  float* pdf) const {
    if (hit.valued && !partner && sameBits(wi, hit.value.wi)) {
      *pdf = hit.value.pdf;
      return hit.value.f;
    }
    return bsdfMixEvalPdf(bsdf, partner, si.partnerWeight, wo, wi, pdf);
  }
  bool bsdfSample(const Bsdf& bsdf, Vec3f wo, float uc, Vec2f u, BsdfSample* bs) const {
    if (!hit.sampled) return envgi::bsdfSample(bsdf, wo, uc, u, bs, true);
    *bs = hit.sample;
    return hit.sampleTaken;
  }
};

// A ray that escaped, where lanes found where it meets the map (uv) and, for the camera's rays,
// the radiance there: pathAddEscape's parts.
struct FoundEscapeParts {
  const EnvironmentMapView& env;
  Vec2f uv;
  const Color* radiance;  // else looked up at uv
  Vec2f mapUV(const Ray&) const { return uv; }
  Color mapRadiance(Vec2f at) const { return radiance ? *radiance : env.lookupUV(at); }
};

}  // namespace envgi
