// The paper's first pass (Section 3): photons leave the environment map (its Algorithm 1
// density), the area lights and the delta lights, bounce with Russian roulette by albedo
// through glass and mirrors, and are handed to a store callback at every non-specular hit
// after the first.
// Host/device: the store callback and the tracer are template parameters.
#pragma once

#include "sampling/Roulette.h"
#include "sampling/Sampler.h"
#include "scene/SceneView.h"

namespace envgi {

struct Photon {
  Vec3f p;
  Vec3f wi;     // unit direction the photon came from (pointing away from the surface)
  Vec3f n;      // geometric normal where it was stored, facing wi
  Color power;  // flux carried, already divided by the number of photons emitted
};

struct PhotonEmitter {
  Vec3f center;        // of the scene's bounding sphere
  float radius = 1.f;
  float envProb = 1.f; // chance a photon leaves the environment rather than an area light
  float deltaProb = 0.f;  // chance it leaves a delta light (the area lights have the rest)

  // False when nothing in the scene emits (a black map and no area or delta lights): no photons.
  ENVGI_HD bool emitsLight(const SceneView& sc) const {
    return envProb > 0.f || sc.lightCount > 0 || deltaProb > 0.f;
  }

  // Origin, direction and flux (times the photon count) of one emitted photon.
  ENVGI_HD bool emit(const SceneView& sc, Sampler& smp, Ray* ray, Color* power) const {
    float uSel = smp.get1D();
    Vec2f u1 = smp.get2D(), u2 = smp.get2D();
    if (uSel < envProb && sc.hasEnvironment) {
      // Direction by the map's luminance (Algorithm 1's density, never the MIS-compensated
      // one); origin on a disk facing it that covers the bounding sphere.
      EnvSample es = sc.env.sampleEmission(u1);
      if (!(es.pdf > 0.f) || isBlack(es.radiance)) return false;
      Frame f = Frame::fromNormal(es.dir);
      Vec2f d = sampleConcentricDisk(u2);
      ray->o = center + (es.dir + f.s * d.x + f.t * d.y) * radius;
      ray->d = -es.dir;
      ray->tMax = INFINITY;
      *power = es.radiance * (kPi * radius * radius / (es.pdf * envProb));
      return true;
    }
    float areaProb = 1.f - envProb - deltaProb;
    if (deltaProb > 0.f && (sc.lightCount == 0 || !(uSel < envProb + areaProb))) {
      // A delta light, all alike: a sun's photons cross a disk covering the bounding sphere
      // along its direction, a point light's leave it uniformly over the sphere, a spot's over
      // its cone.
      int m = sc.deltaLightCount;
      const DeltaLight& l = sc.deltaLights[uniformLightIndex((uSel - envProb - areaProb) / deltaProb, m)];
      float pick = deltaProb / float(m);
      ray->tMax = INFINITY;
      if (isSpot(l)) {
        // A spot: uniform over its cone, each photon carrying the falloff along its direction.
        ray->o = l.v;
        ray->d = Frame::fromNormal(l.axis).toWorld(sampleUniformCone(u1, l.cosCutoff));
        *power = l.value * (spotFalloff(l, ray->d) / (uniformConePdf(l.cosCutoff) * pick));
      } else if (l.point) {
        ray->o = l.v;
        ray->d = sampleUniformSphere(u1);
        *power = l.value * (4.f * kPi / pick);
      } else {
        Frame f = Frame::fromNormal(l.v);
        Vec2f d = sampleConcentricDisk(u2);
        ray->o = center + (-l.v + f.s * d.x + f.t * d.y) * radius;
        ray->d = l.v;
        *power = l.value * (kPi * radius * radius / pick);
      }
      return !isBlack(*power);
    }
    if (sc.lightCount == 0) return false;
    float pmf, areaPdf;
    Vec3f p, n;
    Color Le;
    sampleAreaLight(sc, u2, u1, &pmf, &p, &n, &Le, &areaPdf);
    Vec2f u3 = smp.get2D();
    Vec3f dir = Frame::fromNormal(n).toWorld(sampleCosineHemisphere(u3));
    ray->o = offsetRayOrigin(p, n, dir, 0.f);
    ray->d = normalize(dir);
    ray->tMax = INFINITY;
    // Le cos / (pdf_area pdf_dir) with pdf_dir = cos / pi.
    *power = Le * (kPi / (pmf * areaPdf * areaProb));
    return true;
  }
};

// Importance (flux) transport through refraction keeps the eta^2 that radiance loses.
ENVGI_INLINE Color adjointWeight(const Bsdf& b, Vec3f woLocal, const BsdfSample& bs) {
  return bs.weight * bsdfEtaSquared(b, woLocal, bs.wi);
}

// store(si, wiWorld, power, caustic, bounces) is called at each non-specular hit after the
// first bounce; caustic is true when every bounce before it was specular (light -> S+ -> here).
// A masked surface is met by every photon that reaches it, which is stored there whole, as
// the light arriving there (a camera ray that stops there reflects all of it); the photon then
// goes on through with the chance 1 - opacity (SceneView::stopsAtMask), unscattered and not
// counted as a bounce, or scatters. maxDepth counts both.
template <class Tracer, class Store>
ENVGI_HD int tracePhoton(const SceneView& sc, const Tracer& tracer, Ray ray, Color power, Sampler& smp, int maxDepth,
                         Store&& store) {
  bool specularOnly = true;
  int stored = 0, bounces = 0;
  for (int depth = 0; depth < maxDepth; ++depth) {
    Hit h;
    if (!tracer.intersectSurface(ray, &h)) break;
    SurfaceInteraction si = sc.interaction(ray, h);
    BsdfScratch textured;
    const Bsdf& bsdf = sc.bsdfAt(si, &textured);
    Vec3f wi = -ray.d;
    if (!bsdfIsDelta(bsdf) && bounces > 0) {
      store(si, wi, power, specularOnly, bounces);
      ++stored;
    }
    if (sc.hasMasks && !sc.stopsAtMask(ray, h)) {
      ray.o = offsetRayOrigin(si.p, si.ng, ray.d, si.t);
      ray.tMax = INFINITY;
      continue;
    }
    ++bounces;
    Vec3f woLocal = si.shading.toLocal(wi);
    BsdfSample bs;
    float uc = smp.get1D();
    Vec2f ub = smp.get2D();
    if (!bsdfSample(bsdf, woLocal, uc, ub, &bs)) break;
    Color w = adjointWeight(bsdf, woLocal, bs);
    specularOnly = specularOnly && bs.delta;
    // Russian roulette by albedo: survivors keep roughly the same power.
    if (!russianRoulette(&w, smp.get1D(), 1.f)) break;
    power = power * w;
    Vec3f d = si.shading.toWorld(bs.wi);
    ray.o = offsetRayOrigin(si.p, si.ng, d, si.t);
    ray.d = d;
    ray.tMax = INFINITY;
  }
  return stored;
}

// One photon from the lights: its own random stream (streamSeed, index, sampleIndex), emitted
// and traced; store as tracePhoton's. The photon-map pass and SPPM's photon step, on either
// device, start every photon here.
template <class Tracer, class Store>
ENVGI_HD void shootPhoton(const SceneView& sc, const Tracer& tracer, const PhotonEmitter& emitter, uint32_t streamSeed,
                          uint64_t index, uint32_t sampleIndex, int maxDepth, Store&& store) {
  Sampler smp;
  smp.type = SamplerType::Independent;
  smp.seed = streamSeed;
  smp.start(index, sampleIndex);
  Ray ray;
  Color power;
  if (!emitter.emit(sc, smp, &ray, &power)) return;
  tracePhoton(sc, tracer, ray, power, smp, maxDepth, store);
}

// The photon a map stores at a hit: where, from where, the normal facing it, and its power.
ENVGI_INLINE Photon makePhoton(const SurfaceInteraction& si, Vec3f wi, Color power) {
  return Photon{si.p, wi, faceForward(si.ng, wi), power};
}

}  // namespace envgi
