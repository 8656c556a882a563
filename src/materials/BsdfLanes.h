// What every material kind's batch form shares (RoughPlasticLanes, RoughConductorLanes): the
// lanes' directions and draws in, their samples or values out, and the accessors. A kind adds
// its own steps' arrays, takes() and its sample() and eval().
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

struct BsdfLanes {
  // In: each lane's wo in its shading frame (both steps), its pair (sample) or wi (eval).
  std::vector<float> woX, woY, woZ, u0, u1;
  // wi: sample's out, eval's in. value and pdf: sample's weight and density, eval's value and
  // density; ok: whether the sample counts (sample), whether both directions are above the
  // surface (eval).
  std::vector<float> wiX, wiY, wiZ, valueR, valueG, valueB, pdf;
  std::vector<unsigned char> ok;

  void resizeShared(size_t n) {
    for (std::vector<float>* a : {&woX, &woY, &woZ, &u0, &u1, &wiX, &wiY, &wiZ, &valueR, &valueG, &valueB, &pdf})
      a->resize(n);
    ok.resize(n);
  }

  // A sample's lane j: wo and the pair; afterwards, false where bsdfSample gives no sample, else
  // the sample in *s.
  void setSample(int j, Vec3f wo, Vec2f u) { woX[j] = wo.x, woY[j] = wo.y, woZ[j] = wo.z, u0[j] = u.x, u1[j] = u.y; }
  bool sampleOf(int j, BsdfSample* s) const {
    s->wi = Vec3f(wiX[j], wiY[j], wiZ[j]);
    s->weight = Color(valueR[j], valueG[j], valueB[j]);
    s->pdf = pdf[j];
    s->delta = false;
    return ok[j] != 0;
  }
  // An evaluation's lane j: wo and wi; afterwards, bsdfEvalPdf's value and density.
  void setEval(int j, Vec3f wo, Vec3f wi) {
    woX[j] = wo.x, woY[j] = wo.y, woZ[j] = wo.z, wiX[j] = wi.x, wiY[j] = wi.y, wiZ[j] = wi.z;
  }
  BsdfEvaluation evalOf(int j) const {
    BsdfEvaluation e;
    e.wi = Vec3f(wiX[j], wiY[j], wiZ[j]);
    e.f = ok[j] ? Color(valueR[j], valueG[j], valueB[j]) : Color(0.f);
    e.pdf = ok[j] ? pdf[j] : 0.f;
    return e;
  }
};

}  // namespace envgi
