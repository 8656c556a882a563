#include "scene/Scene.h"

#include <stdexcept>

#include "envmap/CollapsedMap.h"
#include "materials/BsdfFactory.h"

namespace envgi {

namespace {
// Whether material `index`, or any a blend of it may choose, needs the frame along dp/du.
bool needsTangentFrame(const std::vector<Bsdf>& bsdfs, int index, int depth = 0) {
  const Bsdf& b = bsdfs[size_t(index)];
  if (!bsdfIsBlend(b) || depth > kMaxBlendDepth) return bsdfNeedsTangentFrame(b);
  return needsTangentFrame(bsdfs, b.blend0, depth + 1) || needsTangentFrame(bsdfs, b.blend1, depth + 1);
}
}  // namespace

void Scene::finalize() {
  if (bsdfs.empty()) bsdfs.push_back(Bsdf{});
  // A rough plastic whose alpha or ior changed since loading reads the tables of its new ones.
  for (Bsdf& b : bsdfs) attachRoughCoat(b);
  // The collapsed map, for the points strategy: made here so every device reads the same lights.
  if (env && integrator.env.strategy == "points") {
    if (integrator.env.pointMethod == "mediancut") env->setPoints(collapseByMedianCut(*env, integrator.env.pointCount));
    else if (integrator.env.pointMethod == "sample")
      env->setPoints(collapseByWeightedSampling(*env, integrator.env.pointCount, sampler.seed));
    else throw std::runtime_error("unknown point_method '" + integrator.env.pointMethod + "' (sample, mediancut)");
  }
  // Embree reads vertices with 16-byte loads: keep one element of slack after the last one.
  for (TriangleMesh& m : meshes) m.positions.reserve(m.positions.size() + 1);
  meshViews_.assign(meshes.size(), MeshView{});
  sphereViews_.assign(spheres.size(), SphereView{});
  lights_.clear();
  Vec3f lo(INFINITY), hi(-INFINITY);
  for (const ShapeEntry& s : shapes) {
    if (s.isSphere) {
      const Sphere& sp = spheres[s.index];
      SphereView& v = sphereViews_[s.index];
      v.center = sp.center;
      v.radius = sp.radius;
      v.axes = sp.axes;
      v.bsdf = s.bsdf;
      v.flipNormals = sp.flipNormals;
      lo = vmin(lo, sp.center - Vec3f(sp.radius));
      hi = vmax(hi, sp.center + Vec3f(sp.radius));
      if (s.emissive) {
        v.light = int(lights_.size());
        lights_.push_back(
            {int(meshes.size() + s.index), 0, s.radiance, 4.f * kPi * sp.radius * sp.radius, s.radianceTexture});
      }
    } else {
      const TriangleMesh& m = meshes[s.index];
      MeshView& v = meshViews_[s.index];
      v.positions = m.positions.data();
      v.normals = m.normals.empty() ? nullptr : m.normals.data();
      v.uvs = m.uvs.empty() ? nullptr : m.uvs.data();
      v.indices = m.indices.data();
      v.triangleCount = int(m.triangleCount());
      v.bsdf = s.bsdf;
      v.anisotropic = s.bsdf >= 0 && size_t(s.bsdf) < bsdfs.size() && needsTangentFrame(bsdfs, s.bsdf);
      for (const Vec3f& p : m.positions) {
        lo = vmin(lo, p);
        hi = vmax(hi, p);
      }
      if (s.emissive) {
        v.lightOffset = int(lights_.size());
        for (size_t t = 0; t < m.triangleCount(); ++t) {
          Vec3f p0 = m.positions[m.indices[3 * t]], p1 = m.positions[m.indices[3 * t + 1]],
                p2 = m.positions[m.indices[3 * t + 2]];
          lights_.push_back(
              {int(s.index), int(t), s.radiance, 0.5f * length(cross(p1 - p0, p2 - p0)), s.radianceTexture});
        }
      }
    }
  }
  for (const MeshView& v : meshViews_)
    if (!v.positions) throw std::runtime_error("internal: mesh without a shape entry");
  if (!(lo.x <= hi.x)) lo = hi = Vec3f(0.f);
  std::vector<float> power(lights_.size());
  for (size_t i = 0; i < lights_.size(); ++i) power[i] = luminance(lights_[i].radiance) * lights_[i].area;
  if (!lights_.empty()) lightTable_ = AliasTable(power.data(), power.size());

  view_ = SceneView{};
  view_.meshes = meshViews_.data();
  view_.meshCount = int(meshViews_.size());
  view_.spheres = sphereViews_.data();
  view_.sphereCount = int(sphereViews_.size());
  view_.bsdfs = bsdfs.data();
  textureViews_.clear();
  for (const Texture& t : textures) {
    textureViews_.push_back(t.params);
    textureViews_.back().texels = t.texels.empty() ? nullptr : t.texels.data();
  }
  view_.textures = textureViews_.data();
  view_.lights = lights_.data();
  view_.lightCount = int(lights_.size());
  if (!lights_.empty()) view_.lightSelect = lightTable_.view();
  view_.deltaLights = deltaLights.empty() ? nullptr : deltaLights.data();
  view_.deltaLightCount = int(deltaLights.size());
  view_.hasEnvironment = env != nullptr;
  for (const Bsdf& b : bsdfs) view_.hasMasks = view_.hasMasks || bsdfIsMasked(b);
  if (env) view_.env = env->view();
  view_.camera = camera;
  view_.boundsMin = lo;
  view_.boundsMax = hi;
}

size_t Scene::triangleCount() const {
  size_t n = 0;
  for (const TriangleMesh& m : meshes) n += m.triangleCount();
  return n;
}

size_t Scene::geometryBytes() const {
  size_t b = 0;
  for (const TriangleMesh& m : meshes) b += m.bytes();
  return b + spheres.size() * sizeof(Sphere);
}

}  // namespace envgi
