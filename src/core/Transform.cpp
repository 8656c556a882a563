#include "core/Transform.h"

#include <stdexcept>

namespace envgi {

Matrix4 invert(const Matrix4& m) {
  // Gauss-Jordan with partial pivoting, in double for accuracy on large scales.
  double a[4][8];
  for (int i = 0; i < 4; ++i)
    for (int j = 0; j < 4; ++j) {
      a[i][j] = m.m[i][j];
      a[i][j + 4] = (i == j) ? 1.0 : 0.0;
    }
  for (int c = 0; c < 4; ++c) {
    int piv = c;
    for (int r = c + 1; r < 4; ++r)
      if (std::fabs(a[r][c]) > std::fabs(a[piv][c])) piv = r;
    if (std::fabs(a[piv][c]) < 1e-12) throw std::runtime_error("transform matrix is singular");
    if (piv != c)
      for (int j = 0; j < 8; ++j) std::swap(a[c][j], a[piv][j]);
    double d = a[c][c];
    for (int j = 0; j < 8; ++j) a[c][j] /= d;
    for (int r = 0; r < 4; ++r) {
      if (r == c) continue;
      double f = a[r][c];
      for (int j = 0; j < 8; ++j) a[r][j] -= f * a[c][j];
    }
  }
  Matrix4 r;
  for (int i = 0; i < 4; ++i)
    for (int j = 0; j < 4; ++j) r.m[i][j] = float(a[i][j + 4]);
  return r;
}

Transform makeTransform(const Matrix4& m) { return {m, invert(m)}; }

Transform translate(Vec3f d) {
  Matrix4 m;
  m.m[0][3] = d.x;
  m.m[1][3] = d.y;
  m.m[2][3] = d.z;
  return makeTransform(m);
}

Transform scale(Vec3f s) {
  Matrix4 m;
  m.m[0][0] = s.x;
  m.m[1][1] = s.y;
  m.m[2][2] = s.z;
  return makeTransform(m);
}

Transform rotate(Vec3f axis, float degrees) {
  if (!(lengthSq(axis) > 0.f) || !isFiniteVec(axis)) throw std::runtime_error("rotate: the axis must be a finite, non-zero vector");
  Vec3f a = normalize(axis);
  float th = degrees * kPi / 180.f;
  float s = std::sin(th), c = std::cos(th);
  Matrix4 m;
  m.m[0][0] = a.x * a.x + (1 - a.x * a.x) * c;
  m.m[0][1] = a.x * a.y * (1 - c) - a.z * s;
  m.m[0][2] = a.x * a.z * (1 - c) + a.y * s;
  m.m[1][0] = a.x * a.y * (1 - c) + a.z * s;
  m.m[1][1] = a.y * a.y + (1 - a.y * a.y) * c;
  m.m[1][2] = a.y * a.z * (1 - c) - a.x * s;
  m.m[2][0] = a.x * a.z * (1 - c) - a.y * s;
  m.m[2][1] = a.y * a.z * (1 - c) + a.x * s;
  m.m[2][2] = a.z * a.z + (1 - a.z * a.z) * c;
  return makeTransform(m);
}

Transform lookAt(Vec3f origin, Vec3f target, Vec3f up) {
  // Each check is written to fail on NaN too: a NaN camera reaches Embree, whose Debian build
  // aborts the program on an invalid ray.
  if (!(isFiniteVec(origin) && isFiniteVec(target) && isFiniteVec(up)))
    throw std::runtime_error("lookat: origin, target and up must be finite");
  if (!(lengthSq(target - origin) > 0.f)) throw std::runtime_error("lookat: origin and target are the same point");
  if (!(lengthSq(up) > 0.f)) throw std::runtime_error("lookat: 'up' is zero");
  Vec3f dir = normalize(target - origin);
  Vec3f left = cross(normalize(up), dir);
  if (!(lengthSq(left) >= 1e-12f)) throw std::runtime_error("lookat: 'up' is parallel to the view direction");
  left = normalize(left);
  Vec3f newUp = cross(dir, left);
  Matrix4 m;
  for (int i = 0; i < 3; ++i) {
    m.m[i][0] = left[i];
    m.m[i][1] = newUp[i];
    m.m[i][2] = dir[i];
    m.m[i][3] = origin[i];
  }
  return makeTransform(m);
}

}  // namespace envgi
