// Lights without area: Mitsuba's `directional` (a sun: irradiance arriving along one direction)
// and `point` (an intensity from one position). Only next-event estimation reaches them, since
// no sampled direction can hit one; they take no MIS weight.
#pragma once

#include "core/Vec.h"

namespace envgi {

struct DeltaLight {
  Vec3f v;      // directional: the unit direction the light travels; point: its position
  Color value;  // directional: irradiance on a surface facing it; point: radiant intensity
  bool point = false;
};

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
  return l.value / d2;
}

}  // namespace envgi
