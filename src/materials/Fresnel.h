// Fresnel equations for dielectrics and conductors.
#pragma once

#include "core/Vec.h"

namespace envgi {

// Unpolarised reflectance at a dielectric interface; eta = n_inside / n_outside, cosThetaI
// measured on the outside (negative: the ray arrives from inside).
ENVGI_INLINE float fresnelDielectric(float cosThetaI, float eta) {
  cosThetaI = clampf(cosThetaI, -1.f, 1.f);
  if (cosThetaI < 0.f) {
    eta = 1.f / eta;
    cosThetaI = -cosThetaI;
  }
  float sin2ThetaI = 1.f - cosThetaI * cosThetaI;
  float sin2ThetaT = sin2ThetaI / (eta * eta);
  if (sin2ThetaT >= 1.f) return 1.f;  // total internal reflection
  float cosThetaT = safeSqrt(1.f - sin2ThetaT);
  float rParl = (eta * cosThetaI - cosThetaT) / (eta * cosThetaI + cosThetaT);
  float rPerp = (cosThetaI - eta * cosThetaT) / (cosThetaI + eta * cosThetaT);
  return 0.5f * (rParl * rParl + rPerp * rPerp);
}

// Reflectance of a conductor with complex index eta + i k, for one channel.
ENVGI_INLINE float fresnelConductor1(float cosThetaI, float eta, float k) {
  cosThetaI = clampf(cosThetaI, 0.f, 1.f);
  float cos2 = cosThetaI * cosThetaI, sin2 = 1.f - cos2;
  float eta2 = eta * eta, k2 = k * k;
  float t0 = eta2 - k2 - sin2;
  float a2plusb2 = safeSqrt(t0 * t0 + 4.f * eta2 * k2);
  float t1 = a2plusb2 + cos2;
  float a = safeSqrt(0.5f * (a2plusb2 + t0));
  float t2 = 2.f * cosThetaI * a;
  float rs = (t1 - t2) / (t1 + t2);
  float t3 = cos2 * a2plusb2 + sin2 * sin2;
  float t4 = t2 * sin2;
  float rp = rs * (t3 - t4) / (t3 + t4);
  float r = 0.5f * (rp + rs);
  return r == r ? clampf(r, 0.f, 1.f) : 1.f;
}

ENVGI_INLINE Color fresnelConductor(float cosThetaI, Color eta, Color k) {
  return {fresnelConductor1(cosThetaI, eta.x, k.x), fresnelConductor1(cosThetaI, eta.y, k.y),
          fresnelConductor1(cosThetaI, eta.z, k.z)};
}

// Refracts wi about n (same side as wi); etap = n_t / n_i. False on total internal reflection.
ENVGI_INLINE bool refractDir(Vec3f wi, Vec3f n, float etap, Vec3f* wt) {
  float cosThetaI = dot(n, wi);
  float sin2ThetaI = fmaxf(0.f, 1.f - cosThetaI * cosThetaI);
  float sin2ThetaT = sin2ThetaI / (etap * etap);
  if (sin2ThetaT >= 1.f) return false;
  float cosThetaT = safeSqrt(1.f - sin2ThetaT);
  *wt = -wi / etap + (cosThetaI / etap - cosThetaT) * n;
  return true;
}

}  // namespace envgi
