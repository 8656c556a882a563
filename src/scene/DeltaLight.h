// Lights without area: Mitsuba's `directional` (a sun: irradiance arriving along one direction),
// `point` (an intensity from one position) and `spot` (a point whose intensity falls off
// linearly in angle from beam_width to cutoff_angle about its axis). Only next-event estimation
// reaches them, since no sampled direction can hit one; they take no MIS weight.
#pragma once

#include "core/Vec.h"

namespace envgi {

struct DeltaLight {
  Vec3f v;      // directional: the unit direction the light travels; point and spot: the position
  Color value;  // directional: irradiance on a surface facing it; point and spot: peak intensity
  bool point = false;  // point or spot
  // A spot's unit axis and its cone: full intensity within beam_width, none beyond cutoff_angle
  // (cosCutoff -2 for a point light, which shines everywhere).
  Vec3f axis = Vec3f(0.f, 0.f, 1.f);
  float cosCutoff = -2.f, cosBeam = -2.f, cutoff = 0.f, invTransition = 0.f;
};

ENVGI_HD inline bool isSpot(const DeltaLight& l) { return l.point && l.cosCutoff >= -1.f; }

// Makes a point light a spot of the given cone (radians, 0 < beam <= cutoff <= pi): the cosines
// and the falloff's slope that spotFalloff reads.
inline void setSpotCone(DeltaLight& l, float cutoff, float beam) {
  l.cutoff = cutoff;
  l.cosCutoff = std::cos(cutoff);
  l.cosBeam = std::cos(beam);
  l.invTransition = cutoff > beam ? 1.f / (cutoff - beam) : 0.f;
}

// Light n of n alike for r in [0, 1): the index next-event estimation and photon emission pick.
ENVGI_HD inline int uniformLightIndex(float r, int n) {
  int i = int(r * float(n));
  return i < 0 ? 0 : (i < n ? i : n - 1);
}

// A spot's intensity towards unit direction d (from the light) over its peak: Mitsuba's falloff,
// 1 inside the beam, linear in angle down to 0 at the cutoff; 1 everywhere for a point light.
ENVGI_HD inline float spotFalloff(const DeltaLight& l, Vec3f d) {
  if (!isSpot(l)) return 1.f;
  float c = dot(d, l.axis);
  if (!(c > l.cosCutoff)) return 0.f;
  if (c >= l.cosBeam) return 1.f;
  return (l.cutoff - std::acos(fminf(c, 1.f))) * l.invTransition;
}

// What the light sends to p: *wi towards it, *dist to it (INFINITY for a directional one), and
// the value that times f cos gives the reflected radiance (irradiance, or intensity / dist^2).
ENVGI_HD inline Color deltaLightIncident(const DeltaLight& l, Vec3f p, Vec3f* wi, float* dist) {
  if (!l.point) {
    *wi = -l.v;
    *dist = INFINITY;
    return l.value;
  }
  Vec3f d = l.v - p;
  float d2 = lengthSq(d);
  if (!(d2 > 0.f)) return Color(0.f);
  *dist = std::sqrt(d2);
  *wi = d / *dist;
  return l.value * (spotFalloff(l, -*wi) / d2);
}

}  // namespace envgi
