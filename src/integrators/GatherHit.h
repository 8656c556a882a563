// What a gather ray brings back from the diffuse-like surface it lands on: direct light by
// one light sample, plus the photon maps' precomputed irradiance (indirect and caustic) times
// the albedo / pi. The photon integrator's final gather and the grid's fill share it; host and
// device.
#pragma once

#include "integrators/DirectIntegrator.h"
#include "integrators/SpecularChain.h"
#include "photon/IrradianceCache.h"

namespace envgi {

// Light leaving gs towards -wi.
template <class Tracer>
ENVGI_HD Color gatherHitRadiance(const SceneView& sc, const Tracer& tracer, const SurfaceInteraction& gs, Vec3f wi,
                                 Sampler& smp, EnvStrategy strategy, const IrradianceCacheView& global,
                                 const IrradianceCacheView& caustic, uint64_t* rays) {
  Vec3f ny = faceForward(gs.ng, -wi);
  return directLighting(sc, tracer, gs, -wi, smp, strategy, 1, 0, rays) +
         diffuseAlbedo(sc.bsdfAt(gs.bsdf, gs.uv)) * kInvPi * (global.irradiance(gs.p, ny) + caustic.irradiance(gs.p, ny));
}

}  // namespace envgi
