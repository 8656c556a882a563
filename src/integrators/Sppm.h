// Stochastic progressive photon mapping (Hachisuka and Jensen 2009). Each pass traces one
// camera path per pixel to its first non-specular surface (a visible point, with direct light
// by MIS there), shoots photons, and gathers them at visible points through a hashed grid;
// per-pixel radii shrink with alpha. This is the host/device part: one function per step of an
// iteration and per element (pixel or photon), which the CPU driver (render/SppmExecutor, oneTBB)
// and the CUDA one (gpu/CudaSppm.cu) both run.
#pragma once

#include "core/Atomic.h"
#include "integrators/DirectIntegrator.h"
#include "photon/HashGrid.h"
#include "photon/PhotonTracing.h"
#include "scene/IntegratorSettings.h"
#include "scene/SceneView.h"

namespace envgi {

struct VisiblePoint {
  Vec3f p;
  Vec3f wo;
  Frame shading;
  Color beta;
  Vec2f uv;  // where the material's textures are read
  Vec2f dpdu, dpdv;  // and its bump map's derivatives (SurfaceInteraction's)
  int bsdf = 0;
  bool valid = false;
};

// Camera path through specular bounces to the first non-delta surface; adds emission seen
// along the way and direct light at the visible point to *Ld.
template <class Tracer>
ENVGI_HD VisiblePoint sppmCameraPath(const SceneView& sc, const Tracer& tracer, Ray ray, Sampler& smp, int maxDepth,
                                     EnvStrategy strategy, Color* Ld, uint64_t* rays) {
  VisiblePoint vp;
  Color beta(1.f);
  for (int depth = 0; depth < maxDepth; ++depth) {
    Hit h;
    ++*rays;
    if (!tracer.intersect(ray, &h)) {
      if (sc.hasEnvironment) *Ld += beta * sc.env.eval(ray.d);
      return vp;
    }
    SurfaceInteraction si = sc.interaction(ray, h);
    Vec3f wo = -ray.d;
    *Ld += beta * sc.emitted(si, wo);
    BsdfScratch textured;
    const Bsdf& bsdf = sc.bsdfAt(si, &textured);
    // Smooth plastic's coat is a mirror: follow it with its sampling probability (what it
    // reflects may be lit, not emitting), and make the visible point on the base otherwise.
    float pDelta = bsdfDeltaProb(bsdf, si.shading.toLocal(wo));
    float uLobe = smp.get1D();
    if (pDelta < 1.f && uLobe >= pDelta) {
      beta = beta / (1.f - pDelta);
      *Ld += beta * directLighting(sc, tracer, si, wo, smp, strategy, 1, 1, rays, true);
      vp.p = si.p;
      vp.wo = wo;
      vp.shading = si.shading;
      vp.beta = beta;
      vp.bsdf = si.bsdf;
      vp.uv = si.uv;
      vp.dpdu = si.dpdu;
      vp.dpdv = si.dpdv;
      vp.valid = true;
      return vp;
    }
    BsdfSample bs;
    float uc = pDelta < 1.f ? uLobe : smp.get1D();  // < pDelta: bsdfSample picks the coat
    Vec2f ub = smp.get2D();
    if (!bsdfSample(bsdf, si.shading.toLocal(wo), uc, ub, &bs) || !bs.delta) return vp;
    beta *= bs.weight;
    Vec3f wi = si.shading.toWorld(bs.wi);
    ray = Ray{offsetRayOrigin(si.p, si.ng, wi, si.t), wi, INFINITY};
  }
  return vp;
}

// A photon's contribution f(wo, wi) beta_vp Phi at one visible point within its radius.
ENVGI_INLINE Color sppmContribution(const SceneView& sc, const VisiblePoint& vp, Vec3f wi, Color power) {
  BsdfScratch textured;
  const Bsdf& b = sc.bsdfAt(vp.bsdf, vp.uv, vp.dpdu, vp.dpdv, &textured);
  Vec3f wiLocal = vp.shading.toLocal(wi);
  float c = std::fabs(wiLocal.z);
  if (c <= 0.f) return Color(0.f);
  return vp.beta * bsdfEval(b, vp.shading.toLocal(vp.wo), wiLocal) * power / c;
}

struct SppmParams {
  size_t photonsPerPass = 100000;
  float initialRadius = 0.f;  // 0: 1% of the scene's bounding-sphere radius
  float alpha = 2.f / 3.f;
  int maxDepth = kSpecularChainDepth;
  uint32_t seed = 0;
  EnvStrategy strategy = EnvStrategy::Alias;
};

// The radius every pixel starts with: the scene's, or 1% of its bounding-sphere radius.
ENVGI_INLINE float sppmInitialRadius(const SppmParams& s, const PhotonEmitter& e) {
  return s.initialRadius > 0.f ? s.initialRadius : 0.01f * e.radius;
}

// Per-pixel SPPM state as flat arrays (host or device memory): the visible point, the photon
// statistics of Hachisuka and Jensen (R^2, N, tau, and this pass's M and Phi) and the sum of
// direct light over passes.
struct SppmPixels {
  VisiblePoint* vp = nullptr;
  Vec3f* vpPos = nullptr;
  char* vpValid = nullptr;
  float* r2 = nullptr;
  float* n = nullptr;
  float* phi = nullptr;  // 3 a pixel, summed by atomics during the photon pass
  uint32_t* m = nullptr;
  Color* tau = nullptr;
  Color* ld = nullptr;
  float* weightSum = nullptr;  // the filter's weights over the passes, for a filter with negative lobes
};

// Camera step for pixel i of pass `pass`: its visible point and direct light. Returns rays.
template <class Tracer>
ENVGI_HD uint64_t sppmCameraStep(const SceneView& sc, const Tracer& tracer, const SppmParams& s, SppmPixels px, int i,
                                 int pass) {
  const Camera& cam = sc.camera;
  Sampler smp;
  smp.type = SamplerType::Independent;
  smp.seed = s.seed;
  smp.start(uint64_t(i), uint32_t(pass));
  float w;
  Ray ray = sampleCameraRay(cam, smp, i % cam.width, i / cam.width, &w);
  Color L(0.f);
  uint64_t rays = 0;
  VisiblePoint vp = sppmCameraPath(sc, tracer, ray, smp, s.maxDepth, s.strategy, &L, &rays);
  // The filter's weight scales all the pass gives the pixel: its direct light, and through the
  // visible point's beta, the photons' flux gathered there.
  vp.beta *= w;
  if (isFiniteVec(L)) px.ld[i] += L * w;
  if (px.weightSum) px.weightSum[i] += w;  // the film then divides by it, as for path (FilmSums)
  px.vp[i] = vp;
  px.vpPos[i] = vp.p;
  px.vpValid[i] = vp.valid && isFiniteVec(vp.beta) && !isBlack(vp.beta);
  return rays;
}

// Photon j of pass `pass` draws from this sampler (shootPhoton's, on SPPM's stream).
ENVGI_INLINE Sampler sppmPhotonSampler(const SppmParams& s, uint64_t j, int pass) {
  return photonSampler(s.seed ^ kSppmPhotonStream, uint64_t(pass) * s.photonsPerPass + j, 1);
}

// Photon j of pass `pass`: traced from the lights, splatted into every visible point within
// its radius (atomics: photons from many threads meet at one pixel). Returns the splats made.
template <class Tracer>
ENVGI_HD uint32_t sppmPhotonStep(const SceneView& sc, const Tracer& tracer, const PhotonEmitter& emitter,
                                 const SppmParams& s, SppmPixels px, const HashGridView& grid, uint64_t j, int pass) {
  uint32_t hits = 0;
  auto splat = [&](const SurfaceInteraction& si, Vec3f wi, Color pw, bool, int) {
    grid.forNeighbours(si.p, [&](int idx) {
      const VisiblePoint& vp = px.vp[idx];
      if (lengthSq(vp.p - si.p) > px.r2[idx]) return;
      Color c = sppmContribution(sc, vp, wi, pw);
      if (!isFiniteVec(c)) return;
      atomicAddRelaxed(&px.phi[3 * idx], c.x);
      atomicAddRelaxed(&px.phi[3 * idx + 1], c.y);
      atomicAddRelaxed(&px.phi[3 * idx + 2], c.z);
      atomicAddRelaxed(&px.m[idx], 1u);
      ++hits;
    });
  };
  shootPhoton(sc, tracer, emitter, sppmPhotonSampler(s, j, pass), s.maxDepth, false, splat);
  return hits;
}

// Progressive radius reduction at pixel i after a photon pass: N' = N + alpha M,
// R'^2 = R^2 N' / (N + M), tau' = (tau + Phi) R'^2 / R^2; then this pass's M and Phi are cleared.
ENVGI_INLINE void sppmUpdateStep(const SppmParams& s, SppmPixels px, int i) {
  uint32_t mi = px.m[i];
  if (mi > 0) {
    Color ph(px.phi[3 * i], px.phi[3 * i + 1], px.phi[3 * i + 2]);
    float nNew = px.n[i] + s.alpha * float(mi);
    float r2New = px.r2[i] * nNew / (px.n[i] + float(mi));
    px.tau[i] = (px.tau[i] + ph) * (r2New / px.r2[i]);
    px.n[i] = nNew;
    px.r2[i] = r2New;
  }
  px.phi[3 * i] = px.phi[3 * i + 1] = px.phi[3 * i + 2] = 0.f;
  px.m[i] = 0;
}

// Pixel i's estimate after `passes` iterations and `photons` photons: the mean direct light
// plus tau / (photons pi R^2).
ENVGI_INLINE Color sppmRadiance(const Color& ldSum, const Color& tau, float r2, int passes, double photons) {
  return ldSum / float(passes) + tau / float(photons * kPi * r2);
}

}  // namespace envgi
