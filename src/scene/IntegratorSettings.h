// What a scene file (or the command line) asks of each integrator: one settings struct per
// integrator, with its defaults and its own fromProperties beside it (pbrt-v4's
// Integrator::Create, Tungsten's PhotonMapSettings). They are plain host data; the render
// layer turns them into the kernels' parameters.
#pragma once

#include <cstddef>
#include <string>

#include "scene/Properties.h"

namespace envgi {

enum class IntegratorType : int { Path = 0, Direct = 1, Photon = 2, Sppm = 3, Grid = 4 };

// Chains of mirror and glass bounces (from the camera in photon and sppm, and from a light)
// end here.
inline constexpr int kSpecularChainDepth = 16;
// max_depth -1 (Mitsuba's "unbounded") in the photon integrators: Russian roulette ends almost
// every path long before, but a chain between perfect mirrors would not end, and the GPU's
// photon tracer holds a slot a bounce.
inline constexpr int kUnboundedChainDepth = 64;
// Russian roulette starts at this path depth (Mitsuba's rr_depth).
inline constexpr int kRouletteDepth = 5;
// The most photons one kd-tree lookup gathers (its buffers live on the stack).
inline constexpr int kMaxPhotonLookup = 512;

// How light samples draw the environment; shared by every integrator.
struct EnvSamplingSettings {
  std::string strategy = "product";    // a name from kStrategyNames
  int pointCount = 64;                 // points: lights in the collapsed map
  std::string pointMethod = "sample";  // points: sample (Algorithm 1 draws) | mediancut
  static EnvSamplingSettings fromProperties(Properties& p);
};

struct PathSettings {
  int maxDepth = -1;  // Mitsuba's meaning: 1 = emitters seen directly, 2 = direct light, -1 = unbounded
  int rrDepth = kRouletteDepth;
  bool hideEmitters = false;
  static PathSettings fromProperties(Properties& p);
};

struct DirectSettings {
  int emitterSamples = -1;  // -1: the strategy's own count (kStrategyNames)
  int bsdfSamples = -1;
  bool hideEmitters = false;
  std::string misHeuristic = "power";  // power, or balance (the paper's Eq. 5-6)
  static DirectSettings fromProperties(Properties& p);
};

// Jensen's two passes; property names after Mitsuba 0.6's photon mapper.
struct PhotonSettings {
  size_t globalPhotons = 250000;
  size_t causticPhotons = 250000;
  int lookupSize = 120;
  float maxRadius = 0.f;  // 0: a fraction of the scene's bounding-sphere radius (globalRadius)
  int gatherSamples = 8;  // final-gather rays per camera sample; 0 reads the global map directly
  bool coneFilter = false;
  int maxDepth = kSpecularChainDepth;
  int rrDepth = kRouletteDepth;
  bool hideEmitters = false;
  float globalRadius(float sceneRadius) const { return maxRadius > 0.f ? maxRadius : 0.05f * sceneRadius; }
  // Caustics are sharper than indirect light: a quarter of the global radius.
  float causticRadius(float sceneRadius) const { return 0.25f * globalRadius(sceneRadius); }
  static PhotonSettings fromProperties(Properties& p);
};

// Progressive photon mapping (Hachisuka and Jensen 2009).
struct SppmSettings {
  int passes = 64;
  size_t photonCount = 100000;  // per pass
  float initialRadius = 0.f;    // 0: 1% of the scene's bounding-sphere radius
  float alpha = 2.f / 3.f;
  int maxDepth = kSpecularChainDepth;
  static SppmSettings fromProperties(Properties& p);
};

// The paper's grid of illumination coefficients: photon maps, then gather rays from every grid
// point, then per pixel direct light plus the grid's interpolated indirect light.
struct GridSettings {
  int resolution = 32;          // grid points along the scene's longest side (others in proportion)
  int gatherRays = 128;         // rays from each grid point before the first camera pass
  int refineRays = 0;           // rays added to each point before every later pass (0: none)
  int maxGatherRays = 1024;     // refinement stops here
  size_t globalPhotons = 200000;
  size_t causticPhotons = 50000;
  int maxDepth = kSpecularChainDepth;
  int rrDepth = kRouletteDepth;
  bool hideEmitters = false;
  // What a grid point keeps: "sh", L1 spherical harmonics of indirect radiance (an irradiance
  // volume, diffuse response only); or "directions", the paper's M coefficients, the radiance
  // along each of M collapsed-map directions, to which each pixel applies its BSDF (docs/grid.md).
  std::string basis = "sh";
  int directions = 64;  // M, for basis "directions"
  static GridSettings fromProperties(Properties& p);
};

struct IntegratorSettings {
  IntegratorType type = IntegratorType::Path;
  EnvSamplingSettings env;
  PathSettings path;
  DirectSettings direct;
  PhotonSettings photon;
  SppmSettings sppm;
  GridSettings grid;

  // Reads the settings `type` takes (and the environment's); the others keep their defaults.
  static IntegratorSettings fromProperties(IntegratorType type, Properties& p);
  // Sets the strategy by name (checked) with its own sample counts (bsdf: BSDF samples only,
  // mis: one of each), not those the scene file set. The collapsed map's strategies may carry
  // their size, as the study names them: points-64, points-draw-256.
  void setStrategy(const std::string& name);
  // The hide_emitters of the integrator `type` runs (SPPM has none: false).
  bool hidesEmitters() const;
};

}  // namespace envgi
