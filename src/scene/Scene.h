// The scene on the host: owns meshes, materials, lights, the environment map and the render
// settings read from a scene file, and hands kernels a SceneView.
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "envmap/EnvironmentMap.h"
#include "sampling/Sampler.h"
#include "scene/SceneView.h"
#include "scene/TriangleMesh.h"

namespace envgi {

struct Sphere {
  Vec3f center;
  float radius = 1.f;
  bool flipNormals = false;
};

// A shape with its material and, when it is an area light, its radiance.
struct ShapeEntry {
  bool isSphere = false;
  size_t index = 0;  // into meshes or spheres
  int bsdf = 0;
  bool emissive = false;
  Color radiance;
};

struct IntegratorSettings {
  std::string type = "path";  // path | direct | photon | sppm
  int maxDepth = -1;          // -1: unbounded (Russian roulette ends paths)
  int rrDepth = 5;
  bool hideEmitters = false;
  int emitterSamples = -1;    // direct: -1 = default for the strategy
  int bsdfSamples = -1;
  std::string strategy = "mis";  // uniform|cosine|bsdf|importance|alias|adaptive|mis|points
  int pointCount = 64;                // points: lights in the collapsed map
  std::string pointMethod = "sample"; // points: sample (Algorithm 1 draws) | mediancut
  // photon (Jensen's two passes; names after Mitsuba 0.6's photon mapper)
  size_t globalPhotons = 250000;
  size_t causticPhotons = 250000;
  int lookupSize = 120;
  float maxRadius = 0.f;  // 0: 5% of the scene's bounding-sphere radius (caustics: a quarter)
  int gatherSamples = 8;  // final-gather rays per camera sample
  bool coneFilter = false;
  // sppm
  int passes = 64;
  size_t photonCount = 100000;  // per pass
  float initialRadius = 0.f;    // 0: 1% of the bounding-sphere radius
  float alpha = 2.f / 3.f;
};

struct SamplerSettings {
  SamplerType type = SamplerType::Independent;
  int sampleCount = 4;
  uint32_t seed = 0;
};

class Scene {
 public:
  std::vector<TriangleMesh> meshes;
  std::vector<Sphere> spheres;
  std::vector<ShapeEntry> shapes;
  std::vector<Bsdf> bsdfs;
  std::unique_ptr<EnvironmentMap> env;
  Camera camera;
  IntegratorSettings integrator;
  SamplerSettings sampler;
  std::string sourcePath;

  // Builds the views, the light list, the bounds and (points strategy) the collapsed map;
  // call after loading and again after changing any of the above.
  void finalize();
  const SceneView& view() const { return view_; }
  size_t triangleCount() const;
  size_t lightCount() const { return lights_.size(); }
  size_t geometryBytes() const;

 private:
  std::vector<MeshView> meshViews_;
  std::vector<SphereView> sphereViews_;
  std::vector<LightPrim> lights_;
  AliasTable lightTable_;
  SceneView view_;
};

}  // namespace envgi
