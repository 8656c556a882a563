// A binary BVH over the scene's triangles as plain data, traversed by the same code on the
// CPU and the GPU (closest hit and any hit), plus the scene's analytic spheres. Built on the
// host by Bvh (Embree's SAH builder), then copied as-is to the device.
#pragma once

#include "scene/SceneView.h"

namespace envgi {

// 32 bytes. Interior: the two children are adjacent, at `index` and `index + 1`. Leaf
// (count > 0): triangles [index, index + count) of BvhView::triangles.
struct BvhNode {
  float lo[3];
  int32_t index;
  float hi[3];
  int32_t count;
};

// A triangle ready for the Moeller-Trumbore test (vertex 0 and two edges), with the mesh
// and primitive it came from so hits read like Embree's. In the scene's tree, primId -1 - k
// stands for instance k instead (BvhInstance); in a group mesh's tree, geomId is unused (-1):
// a hit there reports the placement's.
struct BvhTriangle {
  Vec3f v0, e1, e2;
  int32_t geomId, primId;
};

// An instance's placement of a shapegroup mesh's own tree (built once, in the group's space):
// two levels, as Embree's instancing, so that memory grows with the distinct meshes.
struct BvhInstance {
  Transform toWorld;  // the ray goes into the group's space by its inverse
  int32_t root;       // the group mesh's tree: its root node
  int32_t geomId;     // the placement's geometry id (Scene::geometryId)
};

constexpr int kBvhStackSize = 64;

struct BvhView {
  const BvhNode* nodes = nullptr;
  const BvhTriangle* triangles = nullptr;
  int nodeCount = 0;
  const BvhInstance* instances = nullptr;
  int instanceCount = 0;
  const SphereView* spheres = nullptr;  // tested one by one: scenes hold a handful
  int sphereCount = 0;
  int sphereGeomOffset = 0;  // geometry id of sphere 0 (meshes come first)
  // The scene, where it has masks: a hit that stopsAtMask turns down is passed through, by
  // intersect() and occluded() (intersectSurface() sees every surface). Null: none.
  const SceneView* masks = nullptr;

  // Box slab test against [tMin, tMax]; returns the entry distance or INFINITY on a miss.
  ENVGI_HD static float boxEntry(const BvhNode& n, Vec3f o, Vec3f invD, float tMax) {
    float t0 = 0.f, t1 = tMax;
    for (int a = 0; a < 3; ++a) {
      float tn = (n.lo[a] - o[a]) * invD[a], tf = (n.hi[a] - o[a]) * invD[a];
      if (tn > tf) {
        float s = tn;
        tn = tf;
        tf = s;
      }
      // Widened by 2 ulp-ish (Ize 2013) so grazing rays do not slip between adjacent boxes.
      tf *= 1.0000004f;
      t0 = tn > t0 ? tn : t0;
      t1 = tf < t1 ? tf : t1;
    }
    return t0 <= t1 ? t0 : INFINITY;
  }

  ENVGI_HD static bool triangleHit(const BvhTriangle& tri, const Ray& r, float tMax, float* t, float* u, float* v) {
    Vec3f pv = cross(r.d, tri.e2);
    float det = dot(tri.e1, pv);
    if (det == 0.f) return false;
    float inv = 1.f / det;
    Vec3f tv = r.o - tri.v0;
    float b1 = dot(tv, pv) * inv;
    if (b1 < 0.f || b1 > 1.f) return false;
    Vec3f qv = cross(tv, tri.e1);
    float b2 = dot(r.d, qv) * inv;
    if (b2 < 0.f || b1 + b2 > 1.f) return false;
    float tt = dot(tri.e2, qv) * inv;
    if (!(tt > 0.f && tt < tMax)) return false;
    *t = tt;
    *u = b1;
    *v = b2;
    return true;
  }

  // Nearest root in (0, tMax), computed from the closest approach to the centre so that
  // rays from far away keep their precision.
  ENVGI_HD static bool sphereRoots(const SphereView& s, const Ray& r, float* t0, float* t1) {
    Vec3f oc = r.o - s.center;
    float dd = dot(r.d, r.d);
    float b = dot(oc, r.d) / dd;
    Vec3f closest = oc - r.d * b;
    float h = s.radius * s.radius - dot(closest, closest);
    if (h < 0.f) return false;
    float q = std::sqrt(h / dd);
    *t0 = -b - q, *t1 = -b + q;
    return true;
  }
  ENVGI_HD static bool sphereHit(const SphereView& s, const Ray& r, float tMax, float* t) {
    float t0, t1;
    if (!sphereRoots(s, r, &t0, &t1)) return false;
    float tt = t0 > 0.f ? t0 : t1;
    if (!(tt > 0.f && tt < tMax)) return false;
    *t = tt;
    return true;
  }
  // The nearest crossing in (0, tMax) that a mask does not let through: the far one where the
  // near one passes, as Embree's sphere points report.
  ENVGI_HD bool sphereStop(int i, const Ray& r, float tMax, const SceneView* masks, float* t) const {
    if (!masks) return sphereHit(spheres[i], r, tMax, t);
    float roots[2];
    if (!sphereRoots(spheres[i], r, &roots[0], &roots[1])) return false;
    for (float tt : roots)
      if (tt > 0.f && tt < tMax && !passesMask(masks, r, tt, sphereGeomOffset + i, 0, 0.f, 0.f)) {
        *t = tt;
        return true;
      }
    return false;
  }

  // A candidate hit that a mask lets the ray through.
  ENVGI_HD static bool passesMask(const SceneView* masks, const Ray& r, float t, int geomId, int primId, float u, float v) {
    if (!masks) return false;
    Hit h;
    h.t = t, h.geomId = geomId, h.primId = primId, h.u = u, h.v = v;
    return !masks->stopsAtMask(r, h);
  }

  template <bool AnyHit>
  ENVGI_HD bool traverse(const Ray& r, Hit* hit, const SceneView* masks) const {
    float tMax = r.tMax;
    bool found = false;
    for (int i = 0; i < sphereCount; ++i) {
      float t;
      if (sphereStop(i, r, tMax, masks, &t)) {
        if (AnyHit) return true;
        tMax = t;
        hit->t = t;
        hit->geomId = sphereGeomOffset + i;
        hit->primId = 0;
        hit->u = hit->v = 0.f;
        found = true;
      }
    }
    if (nodeCount == 0) return found;
    // A scene without instances or masks walks a tree with neither test in its leaf loop: on the
    // GPU they sat in the hottest code (buddha, H200: 392 -> 414 M samples/s, grid 379 -> 436).
    if (instanceCount == 0 && !masks) return walk<AnyHit, true, false>(0, r, r, -1, tMax, hit, nullptr) || found;
    return walk<AnyHit, true, true>(0, r, r, -1, tMax, hit, masks) || found;
  }

  // Walks the tree at `root` with `local`, the world ray r moved into an instance's space (or r
  // itself in the scene's tree, Top), lowering tMax to each hit (t is the same along both: the
  // transform is affine and the direction is not renormalised); a hit's t comes back in hit->t.
  // The scene's tree's leaves may hold instances, walked in turn; a hit inside one reports its
  // geomId. Masks hash the world ray. Instances and masks are looked for only where General.
  template <bool AnyHit, bool Top, bool General>
  ENVGI_INLINE bool walk(int root, const Ray& local, const Ray& world, int geomId, float tMax, Hit* hit,
                         const SceneView* masks) const {
    Vec3f invD(1.f / local.d.x, 1.f / local.d.y, 1.f / local.d.z);
    int stack[kBvhStackSize];
    int sp = 0;
    int node = root;
    bool found = false;
    if (boxEntry(nodes[root], local.o, invD, tMax) == INFINITY) return false;
    for (;;) {
      const BvhNode& n = nodes[node];
      if (n.count > 0) {
        for (int i = n.index; i < n.index + n.count; ++i) {
          const BvhTriangle& tri = triangles[i];
          if constexpr (Top && General) {
            if (tri.primId < 0) {
              const BvhInstance& in = instances[-1 - tri.primId];
              Ray l{in.toWorld.inversePoint(world.o), in.toWorld.inverseVector(world.d), tMax};
              if (walk<AnyHit, false, true>(in.root, l, world, in.geomId, tMax, hit, masks)) {
                if (AnyHit) return true;
                tMax = hit->t;
                found = true;
              }
              continue;
            }
          }
          const int g = Top ? tri.geomId : geomId;
          float t, u, v;
          if (triangleHit(tri, local, tMax, &t, &u, &v) && !(General && passesMask(masks, world, t, g, tri.primId, u, v))) {
            if (AnyHit) return true;
            tMax = t;
            hit->t = t;
            hit->geomId = g;
            hit->primId = tri.primId;
            hit->u = u;
            hit->v = v;
            found = true;
          }
        }
      } else {
        // Visit the nearer child first; push the farther one.
        int c0 = n.index, c1 = n.index + 1;
        float d0 = boxEntry(nodes[c0], local.o, invD, tMax), d1 = boxEntry(nodes[c1], local.o, invD, tMax);
        if (d0 != INFINITY || d1 != INFINITY) {
          if (d1 < d0) {
            int c = c0;
            c0 = c1;
            c1 = c;
            float d = d0;
            d0 = d1;
            d1 = d;
          }
          if (d1 != INFINITY) stack[sp++] = c1;
          node = c0;
          continue;
        }
      }
      // Pop, skipping boxes that the current hit already lies in front of.
      for (;;) {
        if (sp == 0) return found;
        node = stack[--sp];
        if (AnyHit || boxEntry(nodes[node], local.o, invD, tMax) != INFINITY) break;
      }
    }
  }

  ENVGI_HD bool intersect(const Ray& r, Hit* hit) const { return traverse<false>(r, hit, masks); }
  ENVGI_HD bool intersectSurface(const Ray& r, Hit* hit) const { return traverse<false>(r, hit, nullptr); }
  ENVGI_HD bool occluded(Vec3f o, Vec3f d, float tMax) const {
    Hit h;
    return traverse<true>(Ray{o, d, tMax}, &h, masks);
  }
};

// The interface the integrators are written against, over the BVH: the GPU's tracer, and the
// CPU executor's when it runs the GPU's kernel bodies.
struct BvhTracer {
  BvhView bvh;
  ENVGI_HD bool intersect(const Ray& r, Hit* h) const { return bvh.intersect(r, h); }
  ENVGI_HD bool occluded(Vec3f o, Vec3f d, float tMax) const { return bvh.occluded(o, d, tMax); }
  ENVGI_HD bool intersectSurface(const Ray& r, Hit* h) const { return bvh.intersectSurface(r, h); }
  // A queue of coherent rays (the camera's, in the CPU's waves), one at a time here.
  template <class Rays, class Out>
  void intersectCoherent(int n, Rays rays, Out out) const {
    for (int i = 0; i < n; ++i) {
      Hit h;
      const bool found = bvh.intersect(rays(i), &h);
      out(i, found, h);
    }
  }
  // A queue of bounce rays or shadow rays, one at a time here too.
  template <class Rays, class Out>
  void intersectMany(int n, Rays rays, Out out) const { intersectCoherent(n, rays, out); }
  template <class Rays, class Out>
  void occludedMany(int n, Rays rays, Out out) const {
    for (int i = 0; i < n; ++i) {
      const Ray& r = rays(i);
      out(i, bvh.occluded(r.o, r.d, r.tMax));
    }
  }
};

}  // namespace envgi
