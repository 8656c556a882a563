// CPU ray tracing through Embree 3: triangle meshes and analytic spheres (sphere points).
#pragma once

#include <embree3/rtcore.h>

#include <cmath>

#include "scene/Scene.h"

namespace envgi {

class EmbreeAccel {
 public:
  explicit EmbreeAccel(const Scene& scene);
  ~EmbreeAccel();
  EmbreeAccel(const EmbreeAccel&) = delete;
  EmbreeAccel& operator=(const EmbreeAccel&) = delete;

  // Embree's precondition on a ray (RayK::valid in its sources): origin and direction within
  // 1.844e18 a coordinate, no NaN. Debian builds Embree with its assertions on, so a ray outside
  // it aborts the program. Such rays (a camera at 3e38, a NaN from a degenerate scene) miss
  // here, and their shadow rays are blocked.
  static bool traceable(const Ray& r) {
    constexpr float kLarge = 1.844e18f;
    return std::fabs(r.o.x) <= kLarge && std::fabs(r.o.y) <= kLarge && std::fabs(r.o.z) <= kLarge &&
           std::fabs(r.d.x) <= kLarge && std::fabs(r.d.y) <= kLarge && std::fabs(r.d.z) <= kLarge && r.tMax == r.tMax;
  }

  bool intersect(const Ray& ray, Hit* hit) const {
    if (!traceable(ray)) return false;
    RTCIntersectContext ctx;
    rtcInitIntersectContext(&ctx);
    RTCRayHit rh;
    fillRay(ray, rh.ray);
    rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
    rh.hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
    rtcIntersect1(scene_, &ctx, &rh);
    if (rh.hit.geomID == RTC_INVALID_GEOMETRY_ID) return false;
    hit->t = rh.ray.tfar;
    hit->geomId = int(rh.hit.geomID);
    hit->primId = int(rh.hit.primID);
    hit->u = rh.hit.u;
    hit->v = rh.hit.v;
    return true;
  }

  bool occluded(Vec3f o, Vec3f d, float tMax) const {
    Ray ray{o, d, tMax};
    if (!traceable(ray)) return true;
    RTCIntersectContext ctx;
    rtcInitIntersectContext(&ctx);
    RTCRay r;
    fillRay(ray, r);
    rtcOccluded1(scene_, &ctx, &r);
    return r.tfar < 0.f;  // Embree sets tfar to -inf on a hit
  }

  RTCScene handle() const { return scene_; }

 private:
  static void fillRay(const Ray& ray, RTCRay& r) {
    r.org_x = ray.o.x;
    r.org_y = ray.o.y;
    r.org_z = ray.o.z;
    r.dir_x = ray.d.x;
    r.dir_y = ray.d.y;
    r.dir_z = ray.d.z;
    r.tnear = 0.f;
    r.tfar = ray.tMax;
    r.mask = 0xFFFFFFFFu;
    r.time = 0.f;
    r.flags = 0;
    r.id = 0;
  }

  RTCDevice device_ = nullptr;
  RTCScene scene_ = nullptr;
};

// The interface the integrators are written against: a CPU tracer over Embree.
struct EmbreeTracer {
  const EmbreeAccel* accel;
  bool intersect(const Ray& r, Hit* h) const { return accel->intersect(r, h); }
  bool occluded(Vec3f o, Vec3f d, float tMax) const { return accel->occluded(o, d, tMax); }
};

}  // namespace envgi
