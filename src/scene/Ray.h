// Rays and ray hits, shared by the CPU (Embree) and GPU tracers.
#pragma once

#include "core/Vec.h"

namespace envgi {

struct Ray {
  Vec3f o, d;
  float tMax = INFINITY;
};

struct Hit {
  float t = INFINITY;
  int geomId = -1;  // meshes first, then spheres (Scene numbering)
  int primId = -1;
  float u = 0.f, v = 0.f;  // barycentrics of vertices 1 and 2 for triangles
  bool valid() const { return geomId >= 0; }
};

// Offsets a ray origin off the surface along the geometric normal, on the side of w. The
// offset grows with the magnitude of the position and with the distance travelled, which is
// where float error in the hit point comes from, so it holds at any scene scale.
ENVGI_INLINE Vec3f offsetRayOrigin(Vec3f p, Vec3f ng, Vec3f w, float hitDistance) {
  float mag = fmaxf(fmaxf(std::fabs(p.x), std::fabs(p.y)), std::fabs(p.z));
  float eps = 1e-5f * (mag + hitDistance) + 1e-7f;
  return p + (dot(w, ng) > 0.f ? ng : -ng) * eps;
}

}  // namespace envgi
