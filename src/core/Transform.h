// Affine transforms as 4x4 row-major matrices; applying them works on host and device.
#pragma once

#include "core/Vec.h"

namespace envgi {

struct Matrix4 {
  float m[4][4] = {{1, 0, 0, 0}, {0, 1, 0, 0}, {0, 0, 1, 0}, {0, 0, 0, 1}};
};

ENVGI_INLINE Matrix4 mul(const Matrix4& a, const Matrix4& b) {
  Matrix4 r;
  for (int i = 0; i < 4; ++i)
    for (int j = 0; j < 4; ++j) {
      float s = 0.f;
      for (int k = 0; k < 4; ++k) s += a.m[i][k] * b.m[k][j];
      r.m[i][j] = s;
    }
  return r;
}

// A transform keeps its inverse, so directions can go both ways without a matrix inversion.
struct Transform {
  Matrix4 mat, inv;

  ENVGI_HD Vec3f point(Vec3f p) const { return apply(mat, p, 1.f); }
  ENVGI_HD Vec3f vector(Vec3f v) const { return linear(mat, v); }
  ENVGI_HD Vec3f translation() const { return {mat.m[0][3], mat.m[1][3], mat.m[2][3]}; }
  // Normals transform by the inverse transpose.
  ENVGI_HD Vec3f normal(Vec3f n) const {
    return {inv.m[0][0] * n.x + inv.m[1][0] * n.y + inv.m[2][0] * n.z,
            inv.m[0][1] * n.x + inv.m[1][1] * n.y + inv.m[2][1] * n.z,
            inv.m[0][2] * n.x + inv.m[1][2] * n.y + inv.m[2][2] * n.z};
  }
  ENVGI_HD Vec3f inversePoint(Vec3f p) const { return apply(inv, p, 1.f); }
  ENVGI_HD Vec3f inverseVector(Vec3f v) const { return linear(inv, v); }
  ENVGI_HD Transform inverse() const { return {inv, mat}; }

  ENVGI_HD static Vec3f apply(const Matrix4& a, Vec3f p, float w) {
    return {a.m[0][0] * p.x + a.m[0][1] * p.y + a.m[0][2] * p.z + a.m[0][3] * w,
            a.m[1][0] * p.x + a.m[1][1] * p.y + a.m[1][2] * p.z + a.m[1][3] * w,
            a.m[2][0] * p.x + a.m[2][1] * p.y + a.m[2][2] * p.z + a.m[2][3] * w};
  }
  // The upper 3x3 only: apply(a, v, 0) would still multiply the translation by zero, which the
  // compiler must keep (0 * inf is NaN), on every ray the camera and the map rotate.
  ENVGI_HD static Vec3f linear(const Matrix4& a, Vec3f v) {
    return {a.m[0][0] * v.x + a.m[0][1] * v.y + a.m[0][2] * v.z, a.m[1][0] * v.x + a.m[1][1] * v.y + a.m[1][2] * v.z,
            a.m[2][0] * v.x + a.m[2][1] * v.y + a.m[2][2] * v.z};
  }
};

ENVGI_INLINE Transform operator*(const Transform& a, const Transform& b) {
  return {mul(a.mat, b.mat), mul(b.inv, a.inv)};
}

// Host-side constructors (Mitsuba's conventions: angles in degrees, lookat maps +z to target).
Matrix4 invert(const Matrix4& m);  // throws std::runtime_error when singular
Transform makeTransform(const Matrix4& m);
Transform translate(Vec3f d);
Transform scale(Vec3f s);
Transform rotate(Vec3f axis, float degrees);
Transform lookAt(Vec3f origin, Vec3f target, Vec3f up);

}  // namespace envgi
