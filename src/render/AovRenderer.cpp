#include "render/AovRenderer.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include <algorithm>

#include "materials/Bsdf.h"
#include "render/PixelKernel.h"
#include "render/WorkerThreads.h"

namespace envgi {

namespace {

// Salts the AOVs' sample sequence apart from the image's, which would otherwise share its pixels'
// first camera samples (harmless, but the two need not be tied).
constexpr uint32_t kAovStream = 0x27d4eb2fu;

// The directional albedo towards the camera, E[f cos / pdf] over BSDF samples: a diffuse
// surface's reflectance exactly, a mirror's or glass's Fresnel colours (what denoisers take),
// where Mitsuba's AOV reads only diffuse terms.
Color albedoTowards(const SceneView& sc, const SurfaceInteraction& si, const Ray& ray, Sampler& smp) {
  BsdfScratch scratch;
  const Bsdf& b = sc.bsdfAt(si, &scratch);
  const Vec3f wo = si.shading.toLocal(-ray.d);
  Color albedo(0.f);
  for (int k = 0; k < kAovAlbedoSamples; ++k) {
    BsdfSample bs;
    float uc = smp.get1D();
    Vec2f ub = smp.get2D();
    if (bsdfSample(b, wo, uc, ub, &bs) && isFiniteVec(bs.weight)) albedo += bs.weight;
  }
  return albedo * (1.f / float(kAovAlbedoSamples));
}

// What one camera sample adds to each AOV channel of its pixel, weighted by w, in acc's order.
struct AovSample {
  const Scene& scene;
  const std::vector<float>& shapeOfGeom;  // each geometry's shape_index
  bool envSeen;
  void add(const Ray& ray, bool found, const Hit& h, float w, Sampler& smp, float* acc) const {
    const SceneView& sc = scene.view();
    size_t c = 0;
    auto put = [&](float v) { acc[c++] += w * v; };
    auto put3 = [&](Vec3f v) { put(v.x), put(v.y), put(v.z); };
    SurfaceInteraction si;
    if (found) si = sc.interaction(ray, h);
    for (const Aov& a : scene.aovs) {
      switch (a.type) {
        case AovType::Albedo: put3(found ? albedoTowards(sc, si, ray, smp) : Color(0.f)); break;
        // Mitsuba's si.t: camera rays start on the near plane, so depth counts from there.
        case AovType::Depth: put(found ? h.t : 0.f); break;
        case AovType::Position: put3(found ? si.p : Vec3f(0.f)); break;
        case AovType::Uv: {
          Vec2f uv = found ? si.uv : Vec2f(0.f, 0.f);
          // interaction() leaves a sphere's (u, v) out unless its material reads them.
          if (found && h.geomId >= sc.meshCount) {
            const SphereView& sp = sc.spheres[h.geomId - sc.meshCount];
            uv = sphereUv(sp, normalize(si.p - sp.center));
          }
          put(uv.x), put(uv.y);
          break;
        }
        case AovType::GeoNormal: put3(found ? si.ng : Vec3f(0.f)); break;
        case AovType::ShNormal: put3(found ? si.shading.n : Vec3f(0.f)); break;
        case AovType::PrimIndex: put(found ? float(h.primId) : -1.f); break;
        case AovType::ShapeIndex: put(found ? shapeOfGeom[size_t(h.geomId)] : -1.f); break;
        // Mitsuba's: where the environment is seen, every ray counts (1); where it is
        // hidden or absent, the share of the rays that met a surface.
        case AovType::Alpha: put(found || envSeen ? 1.f : 0.f); break;
      }
    }
  }
};

}  // namespace

std::vector<ImageChannel> renderAovs(const Scene& scene, const EmbreeAccel& accel, int samples, int threads) {
  const SceneView& sc = scene.view();
  const Camera& cam = sc.camera;
  const int n = std::clamp(samples, 1, kAovMaxSamples);
  const size_t pixels = size_t(cam.width) * size_t(cam.height);
  std::vector<ImageChannel> out;
  for (const Aov& a : scene.aovs)
    for (const std::string& name : aovChannelNames(a)) out.push_back({name, std::vector<float>(pixels, 0.f)});
  const size_t nc = out.size();
  if (nc == 0) return out;
  // Mitsuba's shape_index counts shapes in the file's order; Hit::geomId counts meshes, then
  // instanced meshes, then spheres.
  std::vector<float> shapeOfGeom(scene.meshGeometryCount() + scene.spheres.size(), -1.f);
  for (size_t i = 0; i < scene.shapes.size(); ++i) shapeOfGeom[scene.geometryId(scene.shapes[i])] = float(i);
  const EmbreeTracer tracer{&accel};
  const AovSample aov{scene, shapeOfGeom, scene.env && !scene.integrator.hidesEmitters()};

  auto body = [&](const tbb::blocked_range<int>& rows) {
    std::vector<float> acc(nc);
    for (int y = rows.begin(); y < rows.end(); ++y)
      for (int x = 0; x < cam.width; ++x) {
        std::fill(acc.begin(), acc.end(), 0.f);
        float wsum = 0.f;
        Sampler smp = sequenceSampler({scene.sampler.type, uint32_t(n), scene.sampler.seed ^ kAovStream});
        for (int s = 0; s < n; ++s) {
          float w;
          Ray ray = startCameraSample(cam, smp, x, y, s, &w);
          Hit h;
          const bool found = tracer.intersect(ray, &h);
          wsum += w;
          aov.add(ray, found, h, w, smp, acc.data());
        }
        const size_t pixel = size_t(y) * size_t(cam.width) + size_t(x);
        for (size_t c = 0; c < nc; ++c) out[c].values[pixel] = wsum != 0.f ? acc[c] / wsum : 0.f;
      }
  };
  tbb::task_arena arena(arenaConcurrency(threads));
  arena.execute([&] { tbb::parallel_for(tbb::blocked_range<int>(0, cam.height, 4), body); });
  return out;
}

}  // namespace envgi
