// Small value types for points, directions and colours; usable on host and device.
#pragma once

#include <cstdint>
#include <cstring>

#include "core/Common.h"

namespace envgi {

struct Vec2f {
  float x = 0.f, y = 0.f;
  constexpr Vec2f() = default;
  ENVGI_HD constexpr Vec2f(float x_, float y_) : x(x_), y(y_) {}
};

struct Vec3f {
  float x = 0.f, y = 0.f, z = 0.f;
  constexpr Vec3f() = default;
  ENVGI_HD constexpr Vec3f(float x_, float y_, float z_) : x(x_), y(y_), z(z_) {}
  ENVGI_HD constexpr explicit Vec3f(float s) : x(s), y(s), z(s) {}
  ENVGI_HD float operator[](int i) const { return i == 0 ? x : (i == 1 ? y : z); }
  ENVGI_HD float& operator[](int i) { return i == 0 ? x : (i == 1 ? y : z); }
};

ENVGI_INLINE Vec2f operator+(Vec2f a, Vec2f b) { return {a.x + b.x, a.y + b.y}; }
ENVGI_INLINE Vec2f operator-(Vec2f a, Vec2f b) { return {a.x - b.x, a.y - b.y}; }
ENVGI_INLINE Vec2f operator*(Vec2f a, float s) { return {a.x * s, a.y * s}; }

ENVGI_INLINE Vec3f operator+(Vec3f a, Vec3f b) { return {a.x + b.x, a.y + b.y, a.z + b.z}; }
ENVGI_INLINE Vec3f operator-(Vec3f a, Vec3f b) { return {a.x - b.x, a.y - b.y, a.z - b.z}; }
ENVGI_INLINE Vec3f operator-(Vec3f a) { return {-a.x, -a.y, -a.z}; }
ENVGI_INLINE Vec3f operator*(Vec3f a, Vec3f b) { return {a.x * b.x, a.y * b.y, a.z * b.z}; }
ENVGI_INLINE Vec3f operator/(Vec3f a, Vec3f b) { return {a.x / b.x, a.y / b.y, a.z / b.z}; }
ENVGI_INLINE Vec3f operator*(Vec3f a, float s) { return {a.x * s, a.y * s, a.z * s}; }
ENVGI_INLINE Vec3f operator*(float s, Vec3f a) { return {a.x * s, a.y * s, a.z * s}; }
ENVGI_INLINE Vec3f operator/(Vec3f a, float s) { float inv = 1.f / s; return a * inv; }
ENVGI_INLINE Vec3f& operator+=(Vec3f& a, Vec3f b) { a = a + b; return a; }
ENVGI_INLINE Vec3f& operator-=(Vec3f& a, Vec3f b) { a = a - b; return a; }
ENVGI_INLINE Vec3f& operator*=(Vec3f& a, Vec3f b) { a = a * b; return a; }
ENVGI_INLINE Vec3f& operator*=(Vec3f& a, float s) { a = a * s; return a; }

ENVGI_INLINE float dot(Vec3f a, Vec3f b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
ENVGI_INLINE float absDot(Vec3f a, Vec3f b) { return std::fabs(dot(a, b)); }
ENVGI_INLINE Vec3f cross(Vec3f a, Vec3f b) {
  return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x};
}
ENVGI_INLINE float lengthSq(Vec3f a) { return dot(a, a); }
ENVGI_INLINE float length(Vec3f a) { return std::sqrt(dot(a, a)); }
ENVGI_INLINE Vec3f normalize(Vec3f a) { return a / length(a); }
ENVGI_INLINE Vec3f vmin(Vec3f a, Vec3f b) { return {fminf(a.x, b.x), fminf(a.y, b.y), fminf(a.z, b.z)}; }
ENVGI_INLINE Vec3f vmax(Vec3f a, Vec3f b) { return {fmaxf(a.x, b.x), fmaxf(a.y, b.y), fmaxf(a.z, b.z)}; }
ENVGI_INLINE float maxComponent(Vec3f a) { return fmaxf(a.x, fmaxf(a.y, a.z)); }
ENVGI_INLINE float luminance(Vec3f c) { return luminance(c.x, c.y, c.z); }
ENVGI_INLINE bool isBlack(Vec3f c) { return c.x == 0.f && c.y == 0.f && c.z == 0.f; }
ENVGI_INLINE bool isFiniteVec(Vec3f c) {
  return std::isfinite(c.x) && std::isfinite(c.y) && std::isfinite(c.z);
}
// Equal to the bit (+0 is not -0, a NaN is itself).
ENVGI_INLINE bool sameBits(Vec3f a, Vec3f b) {
  uint32_t x[3], y[3];
  memcpy(x, &a.x, 4), memcpy(x + 1, &a.y, 4), memcpy(x + 2, &a.z, 4);
  memcpy(y, &b.x, 4), memcpy(y + 1, &b.y, 4), memcpy(y + 2, &b.z, 4);
  return x[0] == y[0] && x[1] == y[1] && x[2] == y[2];
}
ENVGI_INLINE Vec3f faceForward(Vec3f n, Vec3f v) { return dot(n, v) < 0.f ? -n : n; }
ENVGI_INLINE Vec3f reflect(Vec3f wo, Vec3f n) { return -wo + 2.f * dot(wo, n) * n; }

using Color = Vec3f;

}  // namespace envgi
