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

// A shape that can start a caustic (a material with a delta lobe), bounded by a sphere: caustic
// photons from every light are aimed at these (Jensen's projection maps, with spheres for the
// map's cells), so that most of them meet glass or a mirror first.
constexpr int kMaxPhotonTargets = 16;
struct PhotonTarget {
  Vec3f center;
  float radius = 0.f;
  float pick = 1.f;     // chance of aiming at this target
  float cdf = 1.f;      // chance of aiming at this target or an earlier one
  float density = 0.f;  // pick over its disk's area, pick / (pi r^2)
};

struct PhotonEmitter {
  Vec3f center;        // of the scene's bounding sphere
  float radius = 1.f;
  float envProb = 1.f; // chance a photon leaves the environment rather than an area light
  float deltaProb = 0.f;  // chance it leaves a delta light (the area lights have the rest)
  PhotonTarget targets[kMaxPhotonTargets];
  int targetCount = 0;  // 0: photons are never aimed

  // An aimed photon's line, for a direction w towards the light: a point of the disk of radius r
  // about target k's centre, facing w, moved back along w until it lies beyond the scene's
  // bounding sphere, so nothing on the line is skipped.
  ENVGI_HD Vec3f aimedOrigin(Vec3f w, int k, Vec2f disk) const {
    const PhotonTarget& t = targets[k];
    Frame f = Frame::fromNormal(w);
    float back = length(t.center - center) + radius + t.radius;
    return t.center + w * back + (f.s * disk.x + f.t * disk.y) * t.radius;
  }
  // The density of aimed lines of direction w through o, per unit area across w: the sum over
  // every target the line passes through (the chosen one counts whatever rounding says).
  ENVGI_HD float aimedDensity(Vec3f o, Vec3f w, int chosen) const {
    float sum = 0.f;
    for (int j = 0; j < targetCount; ++j) {
      Vec3f v = targets[j].center - o;
      if (j == chosen || lengthSq(v - w * dot(v, w)) <= targets[j].radius * targets[j].radius)
        sum += targets[j].density;
    }
    return sum;
  }
  // A point light at p aimed at target k: directions uniform over the cone its sphere subtends
  // (the whole sphere of directions from inside it). 1 - cos of the cone's half-angle, in a form
  // that keeps its digits for small, far spheres.
  ENVGI_HD float aimedConeOneMinusCos(Vec3f p, int k) const {
    float x = targets[k].radius * targets[k].radius / lengthSq(targets[k].center - p);
    return x >= 1.f ? 2.f : x / (1.f + std::sqrt(1.f - x));
  }
  // The density in solid angle of aimed directions w from p: the sum over every target whose
  // sphere the ray meets (the chosen one counts whatever rounding says).
  ENVGI_HD float aimedConeDensity(Vec3f p, Vec3f w, int chosen) const {
    float sum = 0.f;
    for (int j = 0; j < targetCount; ++j) {
      Vec3f v = targets[j].center - p;
      float along = dot(v, w), r2 = targets[j].radius * targets[j].radius;
      bool meets = lengthSq(v) <= r2 || (along > 0.f && lengthSq(v - w * along) <= r2);
      if (j == chosen || meets) sum += targets[j].pick / (2.f * kPi * aimedConeOneMinusCos(p, j));
    }
    return sum;
  }
  // A direction from p uniform within the cone towards target k's sphere (a point or spot light,
  // or a point on an area light, aimed).
  ENVGI_HD Vec3f aimedConeDirection(Vec3f p, int k, Vec2f u) const {
    Vec3f toTarget = targets[k].center - p;
    Frame f = Frame::fromNormal(lengthSq(toTarget) > 0.f ? normalize(toTarget) : Vec3f(0.f, 1.f, 0.f));
    return normalize(f.toWorld(sampleUniformCone(u, 1.f - aimedConeOneMinusCos(p, k))));
  }
  ENVGI_HD int pickTarget(float u) const {
    int k = 0;
    while (k + 1 < targetCount && !(u < targets[k].cdf)) ++k;
    return k;
  }

  // False when nothing in the scene emits (a black map and no area or delta lights): no photons.
  ENVGI_HD bool emitsLight(const SceneView& sc) const {
    return envProb > 0.f || sc.lightCount > 0 || deltaProb > 0.f;
  }

  // Asks for what emit() with this sampler is sure to miss on, the map's emission bin (CPU only).
  void prefetch(const SceneView& sc, Sampler& smp) const {
    float uSel = smp.get1D();
    Vec2f u1 = smp.get2D();
    if (uSel < envProb && sc.hasEnvironment) sc.env.prefetchEmission(u1);
  }

  // Origin, direction and flux (times the photon count) of one emitted photon. Aimed, every
  // light's photons (the map's, the suns', the point lights', the spots' and the area lights')
  // leave only along rays that meet a target, with the flux their density gives (rays that miss
  // every target carry no caustic).
  ENVGI_HD bool emit(const SceneView& sc, Sampler& smp, Ray* ray, Color* power, bool aimed = false) const {
    float uSel = smp.get1D();
    Vec2f u1 = smp.get2D(), u2 = smp.get2D();
    aimed = aimed && targetCount > 0;
    int target = aimed ? pickTarget(smp.get1D()) : -1;
    if (uSel < envProb && sc.hasEnvironment) {
      // Direction by the map's luminance (Algorithm 1's density, never the MIS-compensated
      // one); origin on a disk facing it that covers the bounding sphere.
      EnvSample es = sc.env.sampleEmission(u1);
      if (!(es.pdf > 0.f) || isBlack(es.radiance)) return false;
      Vec2f d = sampleConcentricDisk(u2);
      ray->d = -es.dir;
      ray->tMax = INFINITY;
      if (aimed) {
        ray->o = aimedOrigin(es.dir, target, d);
        *power = es.radiance / (es.pdf * envProb * aimedDensity(ray->o, es.dir, target));
        return true;
      }
      Frame f = Frame::fromNormal(es.dir);
      ray->o = center + (es.dir + f.s * d.x + f.t * d.y) * radius;
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
      if (l.point && aimed) {
        // Uniform within the cone towards the target's sphere; a spot's falloff weighs it (and
        // ends it outside the spot's own cone).
        ray->o = l.v;
        ray->d = aimedConeDirection(l.v, target, u1);
        float falloff = isSpot(l) ? spotFalloff(l, ray->d) : 1.f;
        *power = l.value * (falloff / (pick * aimedConeDensity(l.v, ray->d, target)));
      } else if (isSpot(l)) {
        // A spot: uniform over its cone, each photon carrying the falloff along its direction.
        ray->o = l.v;
        ray->d = Frame::fromNormal(l.axis).toWorld(sampleUniformCone(u1, l.cosCutoff));
        *power = l.value * (spotFalloff(l, ray->d) / (uniformConePdf(l.cosCutoff) * pick));
      } else if (l.point) {
        ray->o = l.v;
        ray->d = sampleUniformSphere(u1);
        *power = l.value * (4.f * kPi / pick);
      } else if (aimed) {
        ray->o = aimedOrigin(-l.v, target, sampleConcentricDisk(u2));
        ray->d = l.v;
        *power = l.value / (pick * aimedDensity(ray->o, -l.v, target));
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
    if (aimed) {
      // From the light's point, uniform within the cone towards the target's sphere: Le cos /
      // (pdf_area pdf_dir), with the cones' summed density; a direction behind the light (the
      // target below its horizon) carries nothing.
      Vec3f d = aimedConeDirection(p, target, u3);
      float cosL = dot(n, d);
      if (!(cosL > 0.f)) return false;
      ray->o = offsetRayOrigin(p, n, d, 0.f);
      ray->d = d;
      ray->tMax = INFINITY;
      *power = Le * (cosL / (pmf * areaPdf * areaProb * aimedConeDensity(p, d, target)));
      return !isBlack(*power);
    }
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
// (aimed at the targets or not) and traced; store as tracePhoton's. The photon-map pass and
// SPPM's photon step, on either device, start every photon here.
ENVGI_INLINE Sampler photonSampler(uint32_t streamSeed, uint64_t index, uint32_t sampleIndex) {
  Sampler smp;
  smp.type = SamplerType::Independent;
  smp.seed = streamSeed;
  smp.start(index, sampleIndex);
  return smp;
}

// Photons [begin, end) on the CPU, a block of 64 at a time: every photon of a block has its
// emission bin asked for (prefetch(j), PhotonEmitter::prefetch) before the first is shot
// (shoot(j)). A large map's table misses the cache on almost every photon, and these misses
// overlap where the photons' own would not (BM_PhotonPassTeapot 0.82x the time).
template <class Prefetch, class Shoot>
inline void shootInPrefetchedBlocks(uint64_t begin, uint64_t end, Prefetch&& prefetch, Shoot&& shoot) {
  constexpr uint64_t kBlock = 64;
  for (uint64_t j0 = begin; j0 < end; j0 += kBlock) {
    const uint64_t j1 = end - j0 < kBlock ? end : j0 + kBlock;
    for (uint64_t j = j0; j < j1; ++j) prefetch(j);
    for (uint64_t j = j0; j < j1; ++j) shoot(j);
  }
}

template <class Tracer, class Store>
ENVGI_HD void shootPhoton(const SceneView& sc, const Tracer& tracer, const PhotonEmitter& emitter, Sampler smp,
                          int maxDepth, bool aimed, Store&& store) {
  Ray ray;
  Color power;
  if (!emitter.emit(sc, smp, &ray, &power, aimed)) return;
  tracePhoton(sc, tracer, ray, power, smp, maxDepth, store);
}
template <class Tracer, class Store>
ENVGI_HD void shootPhoton(const SceneView& sc, const Tracer& tracer, const PhotonEmitter& emitter, uint32_t streamSeed,
                          uint64_t index, uint32_t sampleIndex, int maxDepth, bool aimed, Store&& store) {
  shootPhoton(sc, tracer, emitter, photonSampler(streamSeed, index, sampleIndex), maxDepth, aimed, store);
}

// The photon a map stores at a hit: where, from where, the normal facing it, and its power.
ENVGI_INLINE Photon makePhoton(const SurfaceInteraction& si, Vec3f wi, Color power) {
  return Photon{si.p, wi, faceForward(si.ng, wi), power};
}

}  // namespace envgi
