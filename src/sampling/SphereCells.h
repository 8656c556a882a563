// A sphere cut into n rows by its polar angle and 2n columns by its azimuth, in its own frame:
// the cells of its (u, v) = (azimuth / 2 pi, polar angle / pi), Mitsuba's sphere coordinates.
// A textured sphere light draws a cell by the texture's power over it, then a point uniformly
// (by area) inside; a point's (u, v) gives back its cell.
#pragma once

#include <cmath>

#include "core/Vec.h"

namespace envgi {

ENVGI_INLINE int sphereCellCount(int n) { return 2 * n * n; }

// The cell of (u, v), row-major by v (a NaN coordinate reads as 0).
ENVGI_INLINE int sphereCellOf(Vec2f uv, int n) {
  const float u = fminf(fmaxf(uv.x, 0.f), 1.f), v = fminf(fmaxf(uv.y, 0.f), 1.f);
  int iu = int(u * float(2 * n)), iv = int(v * float(n));
  iu = iu < 0 ? 0 : (iu > 2 * n - 1 ? 2 * n - 1 : iu);
  iv = iv < 0 ? 0 : (iv > n - 1 ? n - 1 : iv);
  return iv * 2 * n + iu;
}

// A cell's share of the unit sphere's area: dphi (cos theta0 - cos theta1) / (4 pi).
ENVGI_INLINE float sphereCellShare(int cell, int n) {
  const int iv = cell / (2 * n);
  const float c0 = std::cos(kPi * float(iv) / float(n)), c1 = std::cos(kPi * float(iv + 1) / float(n));
  return (c0 - c1) / (4.f * float(n));
}

// A unit direction in the sphere's own frame (z the pole, azimuth from x), uniform by area
// over cell `cell` for uniform u.
ENVGI_INLINE Vec3f sampleSphereCell(int cell, int n, Vec2f u) {
  const int iv = cell / (2 * n), iu = cell - iv * 2 * n;
  const float phi = 2.f * kPi * (float(iu) + u.x) / float(2 * n);
  const float c0 = std::cos(kPi * float(iv) / float(n)), c1 = std::cos(kPi * float(iv + 1) / float(n));
  const float z = c0 + (c1 - c0) * u.y;
  const float r = std::sqrt(fmaxf(0.f, 1.f - z * z));
  return {r * std::cos(phi), r * std::sin(phi), z};
}

}  // namespace envgi
