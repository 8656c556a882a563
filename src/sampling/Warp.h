// Warps from the unit square to directions and disks, each with its density.
#pragma once

#include "core/Vec.h"

namespace envgi {

// A draw u in [lo, lo + p) that picked one of several choices (a kind of light, a BSDF's lobe),
// stretched back over [0, 1) for that choice's own draw.
ENVGI_INLINE float stretchedDraw(float u, float lo, float p) {
  float s = (u - lo) / p;
  return s < kOneMinusEpsilon ? s : kOneMinusEpsilon;
}

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

// Uniform over the cap of directions within angle acos(cosMax) of +z (a spot light's cone).
ENVGI_INLINE Vec3f sampleUniformCone(Vec2f u, float cosMax) {
  float z = 1.f - u.x * (1.f - cosMax);
  float r = safeSqrt(1.f - z * z);
  float phi = 2.f * kPi * u.y;
  return {r * std::cos(phi), r * std::sin(phi), z};
}
ENVGI_INLINE float uniformConePdf(float cosMax) { return 1.f / (2.f * kPi * (1.f - cosMax)); }

// A point of a disk as (r cos angle, r sin angle), in two steps: the disk warps below find r
// and the angle, fromPolar calls libm. A batch can run the steps around libm's sine and
// cosine in vector lanes and those one lane at a time, to the same bits.
struct PolarPoint {
  float r, angle;
};
ENVGI_INLINE Vec2f fromPolar(PolarPoint p) { return {p.r * std::cos(p.angle), p.r * std::sin(p.angle)}; }

// Shirley-Chiu concentric map: keeps strata compact, which stratified sequences rely on. The
// centre is r = 0 at angle 0, (0, 0) as fromPolar gives it.
// Both octant pairs' forms are worked out, then one chosen: branch-free, for the lanes.
ENVGI_INLINE PolarPoint concentricDiskPolar(Vec2f u) {
  const float ox = 2.f * u.x - 1.f, oy = 2.f * u.y - 1.f;
  const bool xMajor = std::fabs(ox) > std::fabs(oy);
  const float r = xMajor ? ox : oy;
  const float angle = xMajor ? (kPi / 4.f) * (oy / ox) : kPi / 2.f - (kPi / 4.f) * (ox / oy);
  const bool centre = ox == 0.f && oy == 0.f;
  return {centre ? 0.f : r, centre ? 0.f : angle};
}
ENVGI_INLINE Vec2f sampleConcentricDisk(Vec2f u) { return fromPolar(concentricDiskPolar(u)); }

// Malley's method: cosine-weighted directions about +z, pdf = cos(theta) / pi.
// d: a point of the unit disk (sampleConcentricDisk's), lifted onto the hemisphere.
ENVGI_INLINE Vec3f cosineHemisphereFromDisk(Vec2f d) { return {d.x, d.y, safeSqrt(1.f - d.x * d.x - d.y * d.y)}; }
ENVGI_INLINE Vec3f sampleCosineHemisphere(Vec2f u) { return cosineHemisphereFromDisk(sampleConcentricDisk(u)); }
ENVGI_INLINE float cosineHemispherePdf(float cosTheta) { return cosTheta > 0.f ? cosTheta * kInvPi : 0.f; }

// A point of [0, 1) with density proportional to (1 - x) a + x b (a, b >= 0): the inverse of its
// quadratic cdf, in the form that stays accurate as a approaches b.
ENVGI_INLINE float sampleLinear(float u, float a, float b) {
  if (a == b) return u;
  float x = u * (a + b) / (a + std::sqrt(lerpf(u, a * a, b * b)));
  return x < kOneMinusEpsilon ? x : kOneMinusEpsilon;
}

// The piecewise-linear function through (0, n0), (1/2, n1) and (1, n2) at x in [0, 1].
ENVGI_INLINE float twoLinearPieces(float x, float n0, float n1, float n2) {
  return x < 0.5f ? lerpf(2.f * x, n0, n1) : lerpf(2.f * x - 1.f, n1, n2);
}

// A point of [0, 1) with density proportional to twoLinearPieces(x, n0, n1, n2): a piece by its
// area, then sampleLinear inside it. Uniform where the function is zero throughout.
// (x < k ? x : k is fminf's answer for every x, NaN included, and a loop over many draws
// vectorises it.)
ENVGI_INLINE float sampleTwoLinearPieces(float u, float n0, float n1, float n2) {
  float left = n0 + n1, right = n1 + n2, t = u * (left + right);
  if (!(left + right > 0.f)) return u;
  const float inLeft = t / left, inRight = (t - left) / right;
  if (t < left || !(right > 0.f))
    return 0.5f * sampleLinear(inLeft < kOneMinusEpsilon ? inLeft : kOneMinusEpsilon, n0, n1);
  return 0.5f + 0.5f * sampleLinear(inRight < kOneMinusEpsilon ? inRight : kOneMinusEpsilon, n1, n2);
}

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
