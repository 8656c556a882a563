// The photon map's first pass: shoots photons in deterministic sub-batches until the global and
// caustic maps hold the requested counts, then builds both kd-trees. The photons are traced on
// the CPU (oneTBB, Embree or the GPU's BVH) or by a GPU (gpu/CudaPhotons.cu); either way the
// same seed stores the same photons in the same order.
#pragma once

#include <atomic>
#include <memory>
#include <string>
#include <vector>

#include "accel/BvhView.h"
#include "accel/EmbreeAccel.h"
#include "photon/PhotonMap.h"
#include "scene/Scene.h"

namespace envgi {

// Photons are shot, and the maps' counts checked, in sub-batches of this many.
constexpr int kPhotonSubBatch = 1 << 15;

// What one sub-batch of photons stored, in photon order (and, for one photon, bounce order).
struct PhotonBatch {
  std::vector<Photon> global, caustic;
};

struct PhotonTraceRequest {
  uint64_t first = 0;
  uint32_t seed = 0;
  uint32_t stream = kPhotonMapStream;  // photons are drawn from seed ^ stream
  bool aimed = false;                  // aimed at the emitter's targets (the caustic stream)
  int maxDepth = kSpecularChainDepth;
  bool global = true, caustic = true;  // which maps still want photons
  // The lights and the targets to aim at, made once a pass (makePhotonEmitter walks the
  // specular shapes); a device tracer copies it to its kernels as it is.
  PhotonEmitter emitter;
};

// Traces sub-batches of a photon-map pass on some device.
class PhotonBatchTracer {
 public:
  virtual ~PhotonBatchTracer() = default;
  virtual std::string deviceName() const = 0;
  // How many sub-batches one trace() call does (a GPU wants many photons in flight).
  virtual int subBatchesPerCall() const { return 1; }
  // Photons [r.first, r.first + subBatchesPerCall() * kPhotonSubBatch), emitted from the stream
  // r.seed ^ r.stream: out receives one PhotonBatch a sub-batch.
  virtual void trace(const PhotonTraceRequest& r, std::vector<PhotonBatch>* out) = 0;
};

// The CPU's: oneTBB over chunks of a sub-batch, with Embree or the GPU's BVH as tracer.
std::unique_ptr<PhotonBatchTracer> makeCpuPhotonTracer(const Scene& scene, const EmbreeAccel& accel);
std::unique_ptr<PhotonBatchTracer> makeCpuPhotonTracer(const Scene& scene, const BvhView& bvh);

struct PhotonShootSettings {
  size_t globalPhotons = 250000;   // stored photons wanted in the global map (0: none)
  size_t causticPhotons = 250000;  // and in the caustic map
  int maxDepth = kSpecularChainDepth;
  uint32_t seed = 0;
  bool progress = true;
  // The caustic map from photons aimed at the shapes that can start a caustic (a stream of its
  // own), where those are small beside the scene; false: from the global map's photons.
  bool aimCaustics = true;
  // Precomputed irradiance (Christensen 1999) at every stride-th photon, for final-gather
  // lookups; 0 skips it (nothing reads it unless the photon integrator gathers).
  int irradianceStride = 0;
  int irradianceLookup = 64;
  float irradianceRadius = 0.1f;
  float causticIrradianceRadius = 0.025f;
  // Where photons are traced; null: the CPU with Embree.
  std::shared_ptr<PhotonBatchTracer> tracer;
  // Set (Ctrl-C): the pass stops after the batch in flight and throws RenderCancelled.
  const std::atomic<bool>* cancel = nullptr;
};

struct PhotonShootStats {
  uint64_t emittedGlobal = 0, emittedCaustic = 0;  // photons emitted while each map was filling
  size_t storedGlobal = 0, storedCaustic = 0;
  int causticTargets = 0;  // the spheres the caustic photons were aimed at (0: not aimed)
  double traceSeconds = 0.0, buildSeconds = 0.0;
  size_t bytes = 0;
  std::string device;  // where the photons were traced
};

// The emitter for a scene: bounding sphere, and the environment's share of the emitted power.
// With aim, also the targets caustic photons may be aimed at (which walks the specular shapes'
// points: only the photon-map pass reads them, not SPPM nor a scene radius).
PhotonEmitter makePhotonEmitter(const Scene& scene, bool aim = false);

// With s.tracer null the photons are traced on the CPU with accel.
void shootPhotons(const Scene& scene, const EmbreeAccel& accel, const PhotonShootSettings& s, PhotonMap* global,
                  PhotonMap* caustic, PhotonShootStats* stats);
// s.tracer must be set.
void shootPhotons(const Scene& scene, const PhotonShootSettings& s, PhotonMap* global, PhotonMap* caustic,
                  PhotonShootStats* stats);

// One log line: photons stored and emitted, times, memory.
void logPhotonStats(const PhotonShootStats& st);

// Throws, naming the count and the memory, where maps holding `photons` would take more than
// half of memoryBytes (0: unknown, never refused), at kPhotonPeakBytes each: shootPhotons asks
// this first, so that global_photons 2000000000 is an error line, not a killed process.
// The vector grown while shooting (up to twice its photons), then the map built from it: its
// arrays, plus 17 bytes a photon for its nodes and irradiance cache (85 a photon in all, logged).
constexpr size_t kPhotonPeakBytes = 2 * sizeof(Photon) + PhotonMap::kBytesPerPhoton + 17;
void requirePhotonMapsFit(size_t photons, double memoryBytes);

}  // namespace envgi
