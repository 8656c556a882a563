// Checks shared by the material kinds' lanes tests: a kind's lanes give bsdfSample's and
// bsdfEvalPdf's answers to the bit, on random directions with the hard cases among them.
#pragma once

#include <gtest/gtest.h>

#include <cstring>
#include <string>
#include <vector>

#include "materials/BsdfLanes.h"
#include "sampling/Pcg32.h"
#include "sampling/Warp.h"

namespace envgi {

inline bool sameFloatBits(float a, float b) { return std::memcmp(&a, &b, sizeof(float)) == 0; }

// n lanes of wo (grazing ones and the poles among them) and draws (the disk's centre, the unit
// square's edges) sampled by Lanes and by bsdfSample with the lobe from u. Each lane must agree
// on whether it samples and, where it does, to the bit; seen(lanes, j) is called for those.
// Returns how many lanes gave no sample.
template <class Lanes, class Seen>
int compareSamples(const Bsdf& b, Pcg32& rng, int n, const std::string& what, Seen seen) {
  EXPECT_TRUE(Lanes::takes(b)) << what;
  Lanes lanes;
  lanes.resize(size_t(n));
  std::vector<Vec3f> wos(n);
  std::vector<Vec2f> us(n);
  for (int j = 0; j < n; ++j) {
    Vec3f wo = sampleUniformSphere(Vec2f(rng.nextFloat(), rng.nextFloat()));
    if (j % 7 == 0) wo = normalize(Vec3f(wo.x, wo.y, 1e-4f * wo.z));  // grazing
    if (j == 1) wo = Vec3f(0.f, 0.f, 1.f);
    if (j == 2) wo = Vec3f(0.f, 0.f, -1.f);
    Vec2f u(rng.nextFloat(), rng.nextFloat());
    if (j % 11 == 0) u = Vec2f(0.5f, 0.5f);  // the concentric disk's centre
    if (j % 13 == 0) u = Vec2f(u.x, 0.f);
    if (j % 17 == 0) u = Vec2f(kOneMinusEpsilon, u.y);
    wos[j] = wo, us[j] = u;
    lanes.setSample(j, wo, u);
  }
  lanes.sample(b, n);
  int none = 0;
  for (int j = 0; j < n; ++j) {
    BsdfSample one, inLanes;
    const bool ok = bsdfSample(b, wos[j], 0.f, us[j], &one, true);
    const bool okLanes = lanes.sampleOf(j, &inLanes);
    EXPECT_EQ(ok, okLanes) << what << " lane " << j;
    if (ok != okLanes) continue;
    if (!ok) {
      ++none;
      continue;
    }
    seen(lanes, j);
    EXPECT_TRUE(sameFloatBits(one.wi.x, inLanes.wi.x) && sameFloatBits(one.wi.y, inLanes.wi.y) &&
                sameFloatBits(one.wi.z, inLanes.wi.z) && sameFloatBits(one.weight.x, inLanes.weight.x) &&
                sameFloatBits(one.weight.y, inLanes.weight.y) && sameFloatBits(one.weight.z, inLanes.weight.z) &&
                sameFloatBits(one.pdf, inLanes.pdf) && !inLanes.delta)
        << what << " lane " << j;
  }
  return none;
}

// n lanes of wo and wi on either side (every ninth wi wo's mirror direction), evaluated by
// Lanes and by bsdfEvalPdf: value and density the same to the bit. Returns how many lanes had
// no density.
template <class Lanes>
int compareEvals(const Bsdf& b, Pcg32& rng, int n, const std::string& what) {
  Lanes lanes;
  lanes.resize(size_t(n));
  std::vector<Vec3f> wos(n), wis(n);
  for (int j = 0; j < n; ++j) {
    wos[j] = sampleUniformSphere(Vec2f(rng.nextFloat(), rng.nextFloat()));
    wis[j] = sampleUniformSphere(Vec2f(rng.nextFloat(), rng.nextFloat()));
    if (j % 9 == 0) wis[j] = Vec3f(-wos[j].x, -wos[j].y, wos[j].z);
    lanes.setEval(j, wos[j], wis[j]);
  }
  lanes.eval(b, n);
  int zero = 0;
  for (int j = 0; j < n; ++j) {
    float pdf;
    const Color f = bsdfEvalPdf(b, wos[j], wis[j], &pdf);
    const BsdfEvaluation e = lanes.evalOf(j);
    EXPECT_TRUE(sameBits(f, e.f) && sameFloatBits(pdf, e.pdf) && sameBits(e.wi, wis[j])) << what << " lane " << j;
    zero += pdf == 0.f;
  }
  return zero;
}

}  // namespace envgi
