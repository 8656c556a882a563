// The photon map's first pass on the CPU (Embree, oneTBB): shoots photons in deterministic
// batches until the global and caustic maps hold the requested counts, then builds both
// kd-trees.
#pragma once

#include "accel/EmbreeAccel.h"
#include "photon/PhotonMap.h"
#include "scene/Scene.h"

namespace envgi {

struct PhotonShootSettings {
  size_t globalPhotons = 250000;   // stored photons wanted in the global map (0: none)
  size_t causticPhotons = 250000;  // and in the caustic map
  int maxDepth = kSpecularChainDepth;
  uint32_t seed = 0;
  bool progress = true;
  // Precomputed irradiance (Christensen 1999) at every stride-th photon, for final-gather
  // lookups; 0 skips it (nothing reads it unless the photon integrator gathers).
  int irradianceStride = 0;
  int irradianceLookup = 64;
  float irradianceRadius = 0.1f;
  float causticIrradianceRadius = 0.025f;
};

struct PhotonShootStats {
  uint64_t emittedGlobal = 0, emittedCaustic = 0;  // photons emitted while each map was filling
  size_t storedGlobal = 0, storedCaustic = 0;
  double traceSeconds = 0.0, buildSeconds = 0.0;
  size_t bytes = 0;
};

// The emitter for a scene: bounding sphere, and the environment's share of the emitted power.
PhotonEmitter makePhotonEmitter(const Scene& scene);

void shootPhotons(const Scene& scene, const EmbreeAccel& accel, const PhotonShootSettings& s, PhotonMap* global,
                  PhotonMap* caustic, PhotonShootStats* stats);

}  // namespace envgi
