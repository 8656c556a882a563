// RoughPlasticLanes, rough plastic's batch forms: its samples and its evaluations in lanes are
// bsdfSample's and bsdfEvalPdf's, to the bit.
#include <gtest/gtest.h>

#include <cstring>

#include "materials/BsdfFactory.h"
#include "materials/RoughPlasticLanes.h"
#include "sampling/Pcg32.h"
#include "sampling/Warp.h"

using namespace envgi;

namespace {
bool sameBits(float a, float b) { return std::memcmp(&a, &b, sizeof(float)) == 0; }
}  // namespace

namespace {
// Eight rough plastics with their coat's tables: four roughnesses, one- and two-sided, linear
// and nonlinear bases, two coats.
Bsdf roughPlasticVariant(int variant) {
  Bsdf b;
  b.type = BsdfType::RoughPlastic;
  b.alpha = variant % 4 == 0 ? 0.02f : (variant % 4 == 1 ? 0.12f : (variant % 4 == 2 ? 0.5f : 1.7f));
  b.twoSided = variant % 2 == 0;
  b.nonlinear = variant / 2 % 2 == 1;
  b.reflectance = Color(0.55f, 0.45f, 0.3f);
  b.specularReflectance = variant < 4 ? Color(1.f) : Color(0.9f, 0.8f, 0.6f);
  b.ior = variant < 4 ? 1.49f : 1.8f;
  finishPlastic(b);
  attachRoughCoat(b);
  return b;
}
}  // namespace

// Rough plastic samples in lanes (sample) are bsdfSample's with the lobe
// from u (path's and direct's call), to the bit, or fail where it fails: one- and two-sided,
// linear and nonlinear bases, several roughnesses, wo in both hemispheres and at grazing angles,
// draws at the lobes' boundary and at the unit square's edges and centre.
TEST(RoughPlasticLanes, RoughPlasticSamplesInLanesAreBsdfSampleToTheBit) {
  Pcg32 rng(31);
  int cases = 0, failures = 0, coat = 0, base = 0, none = 0;
  for (int variant = 0; variant < 8; ++variant) {
    const Bsdf b = roughPlasticVariant(variant);
    ASSERT_TRUE(RoughPlasticLanes::takes(b)) << "variant " << variant;
    const int n = 601;
    RoughPlasticLanes lanes;
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
    for (int j = 0; j < n; ++j) {
      BsdfSample one, inLanes;
      const bool ok = bsdfSample(b, wos[j], 0.f, us[j], &one, true);
      const bool okLanes = lanes.sampleOf(j, &inLanes);
      ++cases;
      if (ok != okLanes) {
        ++failures;
        ADD_FAILURE() << "variant " << variant << " lane " << j << ": bsdfSample " << ok << ", lanes " << okLanes;
        continue;
      }
      if (!ok) {
        ++none;
        continue;
      }
      (lanes.coatLobe[j] > 0.5f ? coat : base) += 1;
      EXPECT_TRUE(sameBits(one.wi.x, inLanes.wi.x) && sameBits(one.wi.y, inLanes.wi.y) &&
                  sameBits(one.wi.z, inLanes.wi.z) && sameBits(one.weight.x, inLanes.weight.x) &&
                  sameBits(one.weight.y, inLanes.weight.y) && sameBits(one.weight.z, inLanes.weight.z) &&
                  sameBits(one.pdf, inLanes.pdf) && !inLanes.delta)
          << "variant " << variant << " lane " << j;
    }
  }
  EXPECT_EQ(failures, 0);
  EXPECT_EQ(cases, 8 * 601);
  // Both lobes compared, and the failures' cases reached (a wo below a one-sided surface).
  EXPECT_GT(coat, 300);
  EXPECT_GT(base, 1000);
  EXPECT_GT(none, 300);
}

// Rough plastic evaluations in lanes (eval) are bsdfEvalPdf's, value and
// density, to the bit: one- and two-sided, linear and nonlinear, wo and wi on either side.
TEST(RoughPlasticLanes, RoughPlasticEvaluationsInLanesAreBsdfEvalPdfToTheBit) {
  Pcg32 rng(37);
  int compared = 0, zero = 0;
  for (int variant = 0; variant < 8; ++variant) {
    const Bsdf b = roughPlasticVariant(variant);
    const int n = 503;
    RoughPlasticLanes lanes;
    lanes.resize(size_t(n));
    std::vector<Vec3f> wos(n), wis(n);
    for (int j = 0; j < n; ++j) {
      wos[j] = sampleUniformSphere(Vec2f(rng.nextFloat(), rng.nextFloat()));
      wis[j] = sampleUniformSphere(Vec2f(rng.nextFloat(), rng.nextFloat()));
      if (j % 9 == 0) wis[j] = Vec3f(-wos[j].x, -wos[j].y, wos[j].z);  // the mirror direction
      lanes.setEval(j, wos[j], wis[j]);
    }
    lanes.eval(b, n);
    for (int j = 0; j < n; ++j) {
      float pdf;
      const Color f = bsdfEvalPdf(b, wos[j], wis[j], &pdf);
      const BsdfEvaluation e = lanes.evalOf(j);
      EXPECT_TRUE(sameBits(f, e.f) && sameBits(Vec3f(pdf, 0.f, 0.f), Vec3f(e.pdf, 0.f, 0.f)) &&
                  sameBits(e.wi, wis[j]))
          << "variant " << variant << " lane " << j;
      ++compared;
      zero += pdf == 0.f;
    }
  }
  EXPECT_EQ(compared, 8 * 503);
  EXPECT_GT(zero, 500) << "the directions below the surface were not reached";
  EXPECT_LT(zero, 3000);
}
