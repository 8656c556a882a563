#include "accel/EmbreeAccel.h"

#include <spdlog/spdlog.h>

#include <stdexcept>

namespace envgi {

namespace {
void embreeError(void*, RTCError code, const char* str) {
  spdlog::error("Embree error {}: {}", int(code), str ? str : "");
}
}  // namespace

EmbreeAccel::EmbreeAccel(const Scene& scene) {
  device_ = rtcNewDevice(nullptr);
  if (!device_) throw std::runtime_error("cannot create an Embree device");
  rtcSetDeviceErrorFunction(device_, embreeError, nullptr);
  scene_ = rtcNewScene(device_);
  rtcSetSceneBuildQuality(scene_, RTC_BUILD_QUALITY_HIGH);
  const SceneView& sv = scene.view();
  for (int i = 0; i < sv.meshCount; ++i) {
    const MeshView& m = sv.meshes[i];
    const TriangleMesh& tm = scene.meshes[size_t(i)];
    RTCGeometry g = rtcNewGeometry(device_, RTC_GEOMETRY_TYPE_TRIANGLE);
    // Shared, not copied: Scene::finalize leaves one element of padding after the vertices,
    // which Embree's 16-byte loads need.
    rtcSetSharedGeometryBuffer(g, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3, m.positions, 0, sizeof(Vec3f),
                               tm.positions.size());
    rtcSetSharedGeometryBuffer(g, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3, m.indices, 0, 3 * sizeof(uint32_t),
                               size_t(m.triangleCount));
    rtcCommitGeometry(g);
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
    rtcCommitGeometry(g);
    rtcAttachGeometryByID(scene_, g, unsigned(sv.meshCount + i));
    rtcReleaseGeometry(g);
  }
  rtcCommitScene(scene_);
  if (rtcGetDeviceError(device_) != RTC_ERROR_NONE) throw std::runtime_error("Embree failed to build the scene");
}

EmbreeAccel::~EmbreeAccel() {
  if (scene_) rtcReleaseScene(scene_);
  if (device_) rtcReleaseDevice(device_);
}

}  // namespace envgi
