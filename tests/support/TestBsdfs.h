// The plainest materials, built in code for material and integrator tests.
#pragma once

#include "materials/Bsdf.h"

namespace envgi::test {

inline Bsdf diffuse(float rho) {
  Bsdf b;
  b.reflectance = Color(rho);
  return b;
}

// Mitsuba's conductor of material "none": a perfect mirror.
inline Bsdf mirror() {
  Bsdf b;
  b.type = BsdfType::Conductor;
  b.perfectMirror = true;
  return b;
}

}  // namespace envgi::test
