// Rough plastic's batch forms: its samples, and its values and densities, for many directions
// of one material at once, in steps that are each a loop over plain arrays the compiler
// vectorises (core/Lanes.h), around libm's sine and cosine one lane at a time. Each lane's
// answer is bsdfSample's (the lobe from u) or bsdfEvalPdf's to the bit.
#pragma once

#include <vector>

#include "materials/Bsdf.h"

namespace envgi {

// A BSDF's value f and density pdf for the direction wi, as bsdfEvalPdf gives them.
struct BsdfEvaluation {
  Vec3f wi;
  Color f;
  float pdf = 0.f;
};

struct RoughPlasticLanes {
  // In: each lane's wo in its shading frame (both steps), its pair (sample) or wi (eval).
  std::vector<float> woX, woY, woZ, u0, u1;
  // wi: sample's out, eval's in. value and pdf: sample's weight and density, eval's value and
  // density; ok: whether the sample counts (sample), whether both directions are above the
  // surface (eval).
  std::vector<float> wiX, wiY, wiZ, valueR, valueG, valueB, pdf;
  std::vector<unsigned char> ok;
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

  // Lanes [0, n), all of material b (takes(b)): what bsdfSample(b, wo, 0, u, s, true) gives for
  // each, to the bit: false where it gives no sample, else the sample in *s.
  void setSample(int j, Vec3f wo, Vec2f u) { woX[j] = wo.x, woY[j] = wo.y, woZ[j] = wo.z, u0[j] = u.x, u1[j] = u.y; }
  void sample(const Bsdf& b, int n);
  bool sampleOf(int j, BsdfSample* s) const {
    s->wi = Vec3f(wiX[j], wiY[j], wiZ[j]);
    s->weight = Color(valueR[j], valueG[j], valueB[j]);
    s->pdf = pdf[j];
    s->delta = false;
    return ok[j] != 0;
  }

  // Lanes [0, n), all of material b (takes(b)): what bsdfEvalPdf(b, wo, wi, &pdf) gives for
  // each, to the bit.
  void setEval(int j, Vec3f wo, Vec3f wi) {
    woX[j] = wo.x, woY[j] = wo.y, woZ[j] = wo.z, wiX[j] = wi.x, wiY[j] = wi.y, wiZ[j] = wi.z;
  }
  void eval(const Bsdf& b, int n);
  BsdfEvaluation evalOf(int j) const {
    BsdfEvaluation e;
    e.wi = Vec3f(wiX[j], wiY[j], wiZ[j]);
    e.f = ok[j] ? Color(valueR[j], valueG[j], valueB[j]) : Color(0.f);
    e.pdf = ok[j] ? pdf[j] : 0.f;
    return e;
  }
};

}  // namespace envgi
