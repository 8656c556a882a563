// Rough conductor's batch forms: its samples, and its values and densities, for many directions
// of one material at once, in steps that are each a loop over plain arrays the compiler
// vectorises (core/Lanes.h), around libm's sine and cosine one lane at a time. Each lane's
// answer is bsdfSample's or bsdfEvalPdf's to the bit.
#pragma once

#include "materials/BsdfLanes.h"

namespace envgi {

struct RoughConductorLanes : BsdfLanes {
  // Between the steps: the disk points, polar, then Cartesian.
  std::vector<float> diskR, diskAngle, diskX, diskY;

  // Whether the lanes take this material: a rough conductor of GGX, isotropic, with no texture
  // (nor a normal or bump map).
  static bool takes(const Bsdf& b) {
    return b.type == BsdfType::RoughConductor && b.distribution == MicrofacetType::GGX && !bsdfIsAnisotropic(b) &&
           !bsdfHasTexture(b) && !bsdfIsBlend(b);
  }
  void resize(size_t n);
  // Lanes [0, n) (setSample), all of material b (takes(b)): bsdfSample(b, wo, 0, u, s, true)'s
  // answers, to the bit (sampleOf).
  void sample(const Bsdf& b, int n);
  // Lanes [0, n) (setEval), all of material b (takes(b)): bsdfEvalPdf(b, wo, wi, &pdf)'s
  // answers, to the bit (evalOf).
  void eval(const Bsdf& b, int n);
};

}  // namespace envgi
