// Rough plastic's batch forms: its samples, and its values and densities, for many directions
// of one material at once, in steps that are each a loop over plain arrays the compiler
// vectorises (core/Lanes.h), around libm's sine and cosine one lane at a time. Each lane's
// answer is bsdfSample's (the lobe from u) or bsdfEvalPdf's to the bit.
#pragma once

#include "materials/BsdfLanes.h"

namespace envgi {

struct RoughPlasticLanes : BsdfLanes {
  // Between the steps: wo's (and wi's) z seen from the front, the coat's reflectance at wo, the
  // disk points (polar, then Cartesian), the lobe (1: the coat), each direction's place among
  // the coat's nodes.
  std::vector<float> frontZ, frontZi, fo, diskR, diskAngle, diskX, diskY, coatLobe, coatShare, coatShareI;
  std::vector<int> coatAt, coatAtI;

  // Whether the lanes take this material: a rough plastic of GGX, isotropic, with its coat's
  // tables and no texture (nor a normal or bump map).
  static bool takes(const Bsdf& b) {
    return b.type == BsdfType::RoughPlastic && b.distribution == MicrofacetType::GGX && !bsdfIsAnisotropic(b) &&
           !bsdfHasTexture(b) && !bsdfIsBlend(b) && b.coatNodes > 0;
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
