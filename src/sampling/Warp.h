// Warps from the unit square to directions and disks, each with its density.
#pragma once

#include "core/Vec.h"

namespace envgi {

ENVGI_INLINE Vec3f sampleUniformSphere(Vec2f u) {
  float z = 1.f - 2.f * u.x;
  float r = safeSqrt(1.f - z * z);
  float phi = 2.f * kPi * u.y;
  return {r * std::cos(phi), r * std::sin(phi), z};
}
ENVGI_INLINE float uniformSpherePdf() { return kInv4Pi; }

ENVGI_INLINE Vec3f sampleUniformHemisphere(Vec2f u) {
  float z = u.x;
  float r = safeSqrt(1.f - z * z);
  float phi = 2.f * kPi * u.y;
  return {r * std::cos(phi), r * std::sin(phi), z};
}
ENVGI_INLINE float uniformHemispherePdf() { return kInv2Pi; }

// Shirley-Chiu concentric map: keeps strata compact, which stratified sequences rely on.
ENVGI_INLINE Vec2f sampleConcentricDisk(Vec2f u) {
  float ox = 2.f * u.x - 1.f, oy = 2.f * u.y - 1.f;
  if (ox == 0.f && oy == 0.f) return {0.f, 0.f};
  float r, theta;
  if (std::fabs(ox) > std::fabs(oy)) {
    r = ox;
    theta = (kPi / 4.f) * (oy / ox);
  } else {
    r = oy;
    theta = kPi / 2.f - (kPi / 4.f) * (ox / oy);
  }
  return {r * std::cos(theta), r * std::sin(theta)};
}

// Malley's method: cosine-weighted directions about +z, pdf = cos(theta) / pi.
ENVGI_INLINE Vec3f sampleCosineHemisphere(Vec2f u) {
  Vec2f d = sampleConcentricDisk(u);
  float z = safeSqrt(1.f - d.x * d.x - d.y * d.y);
  return {d.x, d.y, z};
}
ENVGI_INLINE float cosineHemispherePdf(float cosTheta) { return cosTheta > 0.f ? cosTheta * kInvPi : 0.f; }

ENVGI_INLINE Vec2f sampleUniformTriangle(Vec2f u) {
  float b0, b1;
  if (u.x < u.y) {
    b0 = u.x / 2.f;
    b1 = u.y - b0;
  } else {
    b1 = u.y / 2.f;
    b0 = u.x - b1;
  }
  return {b0, b1};
}

}  // namespace envgi
