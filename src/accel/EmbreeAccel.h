// CPU ray tracing through Embree 3: triangle meshes and analytic spheres (sphere points).
#pragma once

#include <embree3/rtcore.h>

#include <atomic>
#include <cmath>
#include <memory>

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

  // Embree's context with what the mask filter reads (Embree passes it to filter functions).
  struct Context {
    RTCIntersectContext rtc;
    bool throughMasks;  // false: intersectSurface, which sees every surface
    // The rays as given, by RTCRay::id: inside an instance the filter sees the ray in the
    // instance's space, and the mask's hash is of the world-space ray (as in envgi's own BVH).
    const Ray* rays = nullptr;
  };

  // Embree reports a hit inside an instance by the instance's id; envgi numbers each placement
  // as a geometry of its own (Scene::geometryId), which is that id.
  static int geometryOf(unsigned geomID, unsigned instID) {
    return int(instID != RTC_INVALID_GEOMETRY_ID ? instID : geomID);
  }

  // The nearest hit; a masked surface that SceneView::stopsAtMask lets the ray through is
  // passed unless throughMasks is false.
  bool intersect(const Ray& ray, Hit* hit, bool throughMasks = true) const {
    if (!traceable(ray)) return false;
    Context ctx;
    rtcInitIntersectContext(&ctx.rtc);
    ctx.throughMasks = throughMasks;
    ctx.rays = &ray;
    RTCRayHit rh;
    fillRayHit(ray, rh);
    rtcIntersect1(scene_, &ctx.rtc, &rh);
    return hitOf(rh, hit);
  }

  // intersect() for n coherent rays (rays(i) the i-th, out(i, found, hit) its answer) in
  // Embree's 16-wide packets, which share traversal steps: a tile's camera rays, in 4 x 4
  // blocks, in 0.83x the time of one at a time. The hits are
  // intersect()'s: the same primitive, u and v to the bit, t within an ulp or two (the packet
  // kernels compute it their own way).
  template <class Rays, class Out>
  void intersectCoherent(int n, Rays rays, Out out) const {
    alignas(64) RTCRayHit16 rh;
    alignas(64) int valid[16];
    Ray given[16];
    Context ctx;
    rtcInitIntersectContext(&ctx.rtc);
    ctx.rtc.flags = RTC_INTERSECT_CONTEXT_FLAG_COHERENT;
    ctx.throughMasks = true;
    ctx.rays = given;
    for (int b = 0; b < n; b += 16) {
      const int m = n - b < 16 ? n - b : 16;
      for (int j = 0; j < 16; ++j) {
        const Ray& r = rays(b + (j < m ? j : 0));
        given[j] = r;
        valid[j] = j < m && traceable(r) ? -1 : 0;
        rh.ray.org_x[j] = r.o.x, rh.ray.org_y[j] = r.o.y, rh.ray.org_z[j] = r.o.z;
        rh.ray.dir_x[j] = r.d.x, rh.ray.dir_y[j] = r.d.y, rh.ray.dir_z[j] = r.d.z;
        rh.ray.tnear[j] = 0.f, rh.ray.tfar[j] = r.tMax, rh.ray.mask[j] = 0xFFFFFFFFu;
        rh.ray.time[j] = 0.f, rh.ray.flags[j] = 0, rh.ray.id[j] = unsigned(j);
        rh.hit.geomID[j] = RTC_INVALID_GEOMETRY_ID;
        rh.hit.instID[0][j] = RTC_INVALID_GEOMETRY_ID;
      }
      rtcIntersect16(valid, scene_, &ctx.rtc, &rh);
      for (int j = 0; j < m; ++j) {
        Hit h;
        const bool found = valid[j] && rh.hit.geomID[j] != RTC_INVALID_GEOMETRY_ID;
        if (found) {
          h.t = rh.ray.tfar[j];
          h.geomId = geometryOf(rh.hit.geomID[j], rh.hit.instID[0][j]);
          h.primId = int(rh.hit.primID[j]);
          h.u = rh.hit.u[j];
          h.v = rh.hit.v[j];
        }
        out(b + j, found, h);
      }
    }
  }

  // intersect() for n rays that need not be coherent (a round's bounce rays), through Embree's
  // stream call (rtcIntersect1M) in chunks of kStreamChunk: it traces a stream faster than one
  // call a ray. The hits are intersect()'s, t to an ulp or two.
  template <class Rays, class Out>
  void intersectMany(int n, Rays rays, Out out) const {
    RTCRayHit rh[kStreamChunk];
    Ray given[kStreamChunk];
    Context ctx = streamContext(given);
    streamChunks(
        n, rays, given,
        [&](int k, const Ray& r) {
          fillRayHit(r, rh[k]);
          rh[k].ray.id = unsigned(k);
        },
        [&](int k) { rtcIntersect1M(scene_, &ctx.rtc, rh, unsigned(k), sizeof(RTCRayHit)); },
        [&](int i, int q) {
          Hit h;
          const bool found = q >= 0 && hitOf(rh[q], &h);  // -1: misses
          out(i, found, h);
        });
  }

  // occluded() for n shadow rays (rays(i) the i-th, out(i, blocked) its answer) through
  // rtcOccluded1M, as intersectMany.
  template <class Rays, class Out>
  void occludedMany(int n, Rays rays, Out out) const {
    RTCRay rr[kStreamChunk];
    Ray given[kStreamChunk];
    Context ctx = streamContext(given);
    streamChunks(
        n, rays, given,
        [&](int k, const Ray& r) {
          fillRay(r, rr[k]);
          rr[k].id = unsigned(k);
        },
        [&](int k) { rtcOccluded1M(scene_, &ctx.rtc, rr, unsigned(k), sizeof(RTCRay)); },
        // -1 (untraceable): blocked, as occluded() says; Embree sets tfar to -inf on a hit.
        [&](int i, int q) { out(i, q < 0 || rr[q].tfar < 0.f); });
  }

  bool occluded(Vec3f o, Vec3f d, float tMax) const {
    Ray ray{o, d, tMax};
    if (!traceable(ray)) return true;
    Context ctx;
    rtcInitIntersectContext(&ctx.rtc);
    ctx.throughMasks = true;
    ctx.rays = &ray;
    RTCRay r;
    fillRay(ray, r);
    rtcOccluded1(scene_, &ctx.rtc, &r);
    return r.tfar < 0.f;  // Embree sets tfar to -inf on a hit
  }

  // Embree's ray for envgi's, written in place field by field (the benchmarks' plain loops use
  // it too: building one apart and copying it whole into a stream made Embree's loop over that
  // stream 15-20% slower).
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
  // The same with its hit cleared, for an intersection.
  static void fillRayHit(const Ray& ray, RTCRayHit& rh) {
    fillRay(ray, rh.ray);
    rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
    rh.hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
  }

  // For tracing with Embree's own calls (the benchmarks' plain loop): a scene with masks needs an
  // EmbreeAccel::Context, which the mask filter reads, in place of a bare RTCIntersectContext.
  RTCScene handle() const { return scene_; }

  // What Embree holds for this scene (its BVHs and any buffers of its own), as its memory
  // monitor counted it while building.
  size_t bytes() const {
    const long long b = bytes_.load();
    return b > 0 ? size_t(b) : 0;
  }

 private:
  // Rays per stream call: the bench's shadow rays took 0.80x the one-ray time in chunks of 64
  // and 0.68x in chunks of 256; a tile of 16 x 16 has 256 paths.
  static constexpr int kStreamChunk = 256;

  // A context for a stream whose k-th ray is given[k], with RTCRay::id k (the mask filter reads
  // it there).
  static Context streamContext(const Ray* given) {
    Context ctx;
    rtcInitIntersectContext(&ctx.rtc);
    ctx.throughMasks = true;
    ctx.rays = given;
    return ctx;
  }

  // The stream calls' loop: n rays in chunks of kStreamChunk. A chunk's rays that Embree can
  // take go to given[k] and fill(k, ray), k their place in the stream; trace(k) traces the k
  // filled; answer(i, q) then answers ray i from place q, or from q = -1 where Embree could not
  // take it.
  template <class Rays, class Fill, class Trace, class Answer>
  static void streamChunks(int n, Rays& rays, Ray* given, Fill fill, Trace trace, Answer answer) {
    int slot[kStreamChunk];
    for (int b = 0; b < n; b += kStreamChunk) {
      const int m = n - b < kStreamChunk ? n - b : kStreamChunk;
      int k = 0;
      for (int j = 0; j < m; ++j) {
        const Ray& r = rays(b + j);
        if (!traceable(r)) continue;
        given[k] = r;
        slot[k] = b + j;
        fill(k, r);
        ++k;
      }
      if (k > 0) trace(k);
      for (int j = 0, q = 0; j < m; ++j) answer(b + j, q < k && slot[q] == b + j ? q++ : -1);
    }
  }

  // An intersection's answer: false where it found nothing, else its hit in envgi's terms.
  static bool hitOf(const RTCRayHit& rh, Hit* hit) {
    if (rh.hit.geomID == RTC_INVALID_GEOMETRY_ID) return false;
    hit->t = rh.ray.tfar;
    hit->geomId = geometryOf(rh.hit.geomID, rh.hit.instID[0]);
    hit->primId = int(rh.hit.primID);
    hit->u = rh.hit.u;
    hit->v = rh.hit.v;
    return true;
  }

  static bool countBytes(void* accel, ssize_t bytes, bool) {
    static_cast<EmbreeAccel*>(accel)->bytes_ += bytes;
    return true;
  }

  RTCDevice device_ = nullptr;
  RTCScene scene_ = nullptr;
  std::atomic<long long> bytes_{0};
  std::unique_ptr<SceneView> masks_;  // the scene's view, for the masked geometries' filter
};

// The interface the integrators are written against: a CPU tracer over Embree.
struct EmbreeTracer {
  const EmbreeAccel* accel;
  bool intersect(const Ray& r, Hit* h) const { return accel->intersect(r, h); }
  bool occluded(Vec3f o, Vec3f d, float tMax) const { return accel->occluded(o, d, tMax); }
  template <class Rays, class Out>
  void intersectCoherent(int n, Rays rays, Out out) const { accel->intersectCoherent(n, rays, out); }
  template <class Rays, class Out>
  void intersectMany(int n, Rays rays, Out out) const { accel->intersectMany(n, rays, out); }
  template <class Rays, class Out>
  void occludedMany(int n, Rays rays, Out out) const { accel->occludedMany(n, rays, out); }
  // Every surface, masked ones included (photon tracing decides at those itself).
  bool intersectSurface(const Ray& r, Hit* h) const { return accel->intersect(r, h, false); }
};

}  // namespace envgi
