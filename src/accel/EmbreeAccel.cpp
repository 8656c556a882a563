#include "accel/EmbreeAccel.h"

#include <spdlog/spdlog.h>

#include <stdexcept>

namespace envgi {

namespace {
void embreeError(void*, RTCError code, const char* str) {
  spdlog::error("Embree error {}: {}", int(code), str ? str : "");
}

// On a masked geometry, for intersect and occluded alike: turns down the hits that the mask
// lets the ray through, and Embree goes on to the next surface.
void maskFilter(const RTCFilterFunctionNArguments* args) {
  const auto* ctx = reinterpret_cast<const EmbreeAccel::Context*>(args->context);
  if (!ctx->throughMasks) return;
  const auto* sv = static_cast<const SceneView*>(args->geometryUserPtr);
  for (unsigned i = 0; i < args->N; ++i) {
    if (args->valid[i] != -1) continue;
    Ray r{{RTCRayN_org_x(args->ray, args->N, i), RTCRayN_org_y(args->ray, args->N, i), RTCRayN_org_z(args->ray, args->N, i)},
          {RTCRayN_dir_x(args->ray, args->N, i), RTCRayN_dir_y(args->ray, args->N, i), RTCRayN_dir_z(args->ray, args->N, i)},
          INFINITY};
    if (ctx->rays) {
      r = ctx->rays[RTCRayN_id(args->ray, args->N, i)];
      r.tMax = INFINITY;
    }
    Hit h;
    // The candidate's distance while the filter runs: the same along the ray inside an
    // instance, whose transform is affine.
    h.t = RTCRayN_tfar(args->ray, args->N, i);
    h.geomId = EmbreeAccel::geometryOf(RTCHitN_geomID(args->hit, args->N, i), RTCHitN_instID(args->hit, args->N, i, 0));
    h.primId = int(RTCHitN_primID(args->hit, args->N, i));
    h.u = RTCHitN_u(args->hit, args->N, i);
    h.v = RTCHitN_v(args->hit, args->N, i);
    if (!sv->stopsAtMask(r, h)) args->valid[i] = 0;
  }
}

// Hands the masked geometries their filter; the others stay without one.
void attachMaskFilter(RTCGeometry g, const SceneView* masks, int bsdf) {
  if (!masks || !bsdfIsMasked(masks->bsdfs[bsdf])) return;
  rtcSetGeometryUserData(g, const_cast<SceneView*>(masks));
  rtcSetGeometryIntersectFilterFunction(g, maskFilter);
  rtcSetGeometryOccludedFilterFunction(g, maskFilter);
}
}  // namespace

EmbreeAccel::EmbreeAccel(const Scene& scene) {
  device_ = rtcNewDevice(nullptr);
  if (!device_) throw std::runtime_error("cannot create an Embree device");
  rtcSetDeviceErrorFunction(device_, embreeError, nullptr);
  rtcSetDeviceMemoryMonitorFunction(device_, countBytes, this);
  scene_ = rtcNewScene(device_);
  rtcSetSceneBuildQuality(scene_, RTC_BUILD_QUALITY_HIGH);
  const SceneView& sv = scene.view();
  if (sv.hasMasks) masks_ = std::make_unique<SceneView>(sv);
  auto triangles = [&](const MeshView& m) {
    RTCGeometry g = rtcNewGeometry(device_, RTC_GEOMETRY_TYPE_TRIANGLE);
    // Shared, not copied: Scene::finalize leaves one element of padding after the vertices,
    // which Embree's 16-byte loads need.
    rtcSetSharedGeometryBuffer(g, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3, m.positions, 0, sizeof(Vec3f),
                               size_t(m.vertexCount));
    rtcSetSharedGeometryBuffer(g, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3, m.indices, 0, 3 * sizeof(uint32_t),
                               size_t(m.triangleCount));
    attachMaskFilter(g, masks_.get(), m.bsdf);
    rtcCommitGeometry(g);
    return g;
  };
  // Each shapegroup mesh that instances place gets one scene of its own (its BVH, built once),
  // and each placement an instance of it: Embree's two-level instancing.
  std::vector<RTCScene> prototypes(scene.prototypes.size(), nullptr);
  for (int i = 0; i < sv.meshCount; ++i) {
    const MeshView& m = sv.meshes[i];
    RTCGeometry g;
    if (size_t(i) < scene.meshes.size()) {
      g = triangles(m);
    } else {
      const MeshInstance& inst = scene.instances[size_t(i) - scene.meshes.size()];
      RTCScene& proto = prototypes[size_t(inst.prototype)];
      if (!proto) {
        proto = rtcNewScene(device_);
        rtcSetSceneBuildQuality(proto, RTC_BUILD_QUALITY_HIGH);
        RTCGeometry t = triangles(m);
        rtcAttachGeometryByID(proto, t, 0);
        rtcReleaseGeometry(t);
        rtcCommitScene(proto);
      }
      g = rtcNewGeometry(device_, RTC_GEOMETRY_TYPE_INSTANCE);
      rtcSetGeometryInstancedScene(g, proto);
      // The first three rows of the row-major 4 x 4 matrix: Embree's 3 x 4 row-major layout.
      rtcSetGeometryTransform(g, 0, RTC_FORMAT_FLOAT3X4_ROW_MAJOR, &inst.toWorld.mat.m[0][0]);
      rtcCommitGeometry(g);
    }
    rtcAttachGeometryByID(scene_, g, unsigned(i));
    rtcReleaseGeometry(g);
  }
  for (int i = 0; i < sv.sphereCount; ++i) {
    const SphereView& s = sv.spheres[i];
    RTCGeometry g = rtcNewGeometry(device_, RTC_GEOMETRY_TYPE_SPHERE_POINT);
    float* v = static_cast<float*>(rtcSetNewGeometryBuffer(g, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT4, 4 * sizeof(float), 1));
    v[0] = s.center.x;
    v[1] = s.center.y;
    v[2] = s.center.z;
    v[3] = s.radius;
    attachMaskFilter(g, masks_.get(), s.bsdf);
    rtcCommitGeometry(g);
    rtcAttachGeometryByID(scene_, g, unsigned(sv.meshCount + i));
    rtcReleaseGeometry(g);
  }
  rtcCommitScene(scene_);
  for (RTCScene p : prototypes)
    if (p) rtcReleaseScene(p);  // the instances hold their own references
  if (rtcGetDeviceError(device_) != RTC_ERROR_NONE) throw std::runtime_error("Embree failed to build the scene");
}

EmbreeAccel::~EmbreeAccel() {
  if (scene_) rtcReleaseScene(scene_);
  if (device_) rtcReleaseDevice(device_);
}

}  // namespace envgi
