// Orthonormal basis around a unit vector; local z is the given normal.
#pragma once

#include "core/Vec.h"

namespace envgi {

struct Frame {
  Vec3f s, t, n;

  // Branchless construction (Duff et al. 2017), stable for every unit normal.
  ENVGI_HD static Frame fromNormal(Vec3f n) {
    float sign = std::copysign(1.f, n.z);
    float a = -1.f / (sign + n.z);
    float b = n.x * n.y * a;
    Frame f;
    f.s = Vec3f(1.f + sign * n.x * n.x * a, sign * b, -sign * n.x);
    f.t = Vec3f(b, sign + n.y * n.y * a, -n.y);
    f.n = n;
    return f;
  }
  // The frame whose s is the tangent dpdu made orthogonal to n (Mitsuba's shading frame, which
  // anisotropic BSDFs orient by); fromNormal where dpdu is zero or along n.
  ENVGI_HD static Frame fromNormalAndTangent(Vec3f n, Vec3f dpdu) {
    Vec3f s = dpdu - n * dot(n, dpdu);
    float l2 = dot(s, s);
    if (!(l2 > 1e-30f && l2 < 1e30f)) return fromNormal(n);
    Frame f;
    f.s = s * (1.f / std::sqrt(l2));
    f.t = cross(n, f.s);
    f.n = n;
    return f;
  }
  ENVGI_HD Vec3f toLocal(Vec3f v) const { return {dot(v, s), dot(v, t), dot(v, n)}; }
  ENVGI_HD Vec3f toWorld(Vec3f v) const { return s * v.x + t * v.y + n * v.z; }
};

}  // namespace envgi
