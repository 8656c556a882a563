// The scene on the host: owns meshes, materials, lights, the environment map and the render
// settings read from a scene file, and hands kernels a SceneView.
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "envmap/EnvironmentMap.h"
#include "scene/Aov.h"
#include "sampling/Sampler.h"
#include "scene/IntegratorSettings.h"
#include "scene/SceneView.h"
#include "scene/TriangleMesh.h"

namespace envgi {

struct Sphere {
  Vec3f center;
  float radius = 1.f;
  bool flipNormals = false;
  Frame axes{{1.f, 0.f, 0.f}, {0.f, 1.f, 0.f}, {0.f, 0.f, 1.f}};
};

// A texture on the host: its parameters and, for a bitmap, the texels its view points into.
struct Texture {
  TextureView params;
  std::vector<Color> texels;
};

// A shape with its material and, when it is an area light, its radiance.
struct ShapeEntry {
  bool isSphere = false;
  size_t index = 0;  // into meshes, spheres or (isInstance) instances
  int bsdf = 0;
  bool emissive = false;
  Color radiance;            // an area light's; with a texture, the texture's mean (its power)
  int radianceTexture = -1;  // an area light's radiance texture, read at the (u, v) it leaves from
  bool isInstance = false;   // a shapegroup's mesh placed by an instance (never a light)
};

// A shapegroup's mesh placed by an instance: prototypes[prototype], in the group's space, under
// toWorld. Every placement shares the prototype's arrays (and, in Embree, its BVH), so memory
// grows with the distinct meshes, not with the instances.
struct MeshInstance {
  int prototype = 0;
  Transform toWorld;
};

struct SamplerSettings {
  SamplerType type = SamplerType::Independent;
  int sampleCount = 4;
  uint32_t seed = 0;
};

class Scene {
 public:
  std::vector<TriangleMesh> meshes;
  std::vector<TriangleMesh> prototypes;  // shapegroups' meshes, which instances place
  std::vector<MeshInstance> instances;
  std::vector<Sphere> spheres;
  std::vector<ShapeEntry> shapes;
  std::vector<Bsdf> bsdfs;
  std::vector<Texture> textures;
  std::unique_ptr<EnvironmentMap> env;
  std::vector<DeltaLight> deltaLights;  // `directional`, `point` and `spot` emitters
  Camera camera;
  IntegratorSettings integrator;
  SamplerSettings sampler;
  std::vector<Aov> aovs;  // Mitsuba's aov integrator's list: channels written beside the image
  bool filmAlpha = false;  // hdrfilm's pixel_format rgba (or xyza, luminance_alpha): an A channel
  std::string sourcePath;

  // Builds the views, the light list, the bounds and (points strategy) the collapsed map;
  // call after loading and again after changing any of the above.
  // Throws where the map's MIS compensation would bias the chosen estimator (no BSDF samples
  // beside its light samples): photon and grid gathers, the collapsed map.
  void requireCompensationCovered() const;
  void finalize();
  const SceneView& view() const { return view_; }
  // Geometry ids (Hit::geomId): the meshes, then the instances, then the spheres.
  size_t meshGeometryCount() const { return meshes.size() + instances.size(); }
  size_t geometryId(const ShapeEntry& e) const {
    return e.isSphere ? meshGeometryCount() + e.index : e.isInstance ? meshes.size() + e.index : e.index;
  }
  // The mesh behind a geometry id below meshGeometryCount(): its own, or its instance's prototype.
  const TriangleMesh& meshOfGeometry(size_t id) const {
    return id < meshes.size() ? meshes[id] : prototypes[size_t(instances[id - meshes.size()].prototype)];
  }
  // Triangles as placed: an instance's count every time it is placed.
  size_t triangleCount() const;
  size_t lightCount() const { return lights_.size(); }
  size_t geometryBytes() const;

 private:
  std::vector<MeshView> meshViews_;
  std::vector<SphereView> sphereViews_;
  std::vector<TextureView> textureViews_;
  std::vector<LightPrim> lights_;
  AliasTable lightTable_;
  std::vector<AliasBin> lightCells_;  // textured light triangles' cell tables (SceneView::lightCells)
  SceneView view_;
};

}  // namespace envgi
