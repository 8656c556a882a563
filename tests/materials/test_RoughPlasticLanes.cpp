// RoughPlasticLanes, rough plastic's batch forms: its samples and its evaluations in lanes are
// bsdfSample's and bsdfEvalPdf's, to the bit.
#include <gtest/gtest.h>

#include "materials/BsdfFactory.h"
#include "support/BsdfLanesChecks.h"
#include "materials/RoughPlasticLanes.h"

using namespace envgi;

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

// Rough plastic samples in lanes (sample) are bsdfSample's with the lobe from u (path's and
// direct's call), to the bit, or fail where it fails: one- and two-sided, linear and nonlinear
// bases, several roughnesses, both lobes.
TEST(RoughPlasticLanes, RoughPlasticSamplesInLanesAreBsdfSampleToTheBit) {
  Pcg32 rng(31);
  int none = 0, coat = 0, base = 0;
  for (int variant = 0; variant < 8; ++variant)
    none += compareSamples<RoughPlasticLanes>(
        roughPlasticVariant(variant), rng, 601, "variant " + std::to_string(variant),
        [&](const RoughPlasticLanes& lanes, int j) { (lanes.coatLobe[j] > 0.5f ? coat : base) += 1; });
  EXPECT_EQ(none + coat + base, 8 * 601);
  // Both lobes compared, and the failures' cases reached (a wo below a one-sided surface).
  EXPECT_GT(coat, 300);
  EXPECT_GT(base, 1000);
  EXPECT_GT(none, 300);
}

// Rough plastic evaluations in lanes (eval) are bsdfEvalPdf's, value and density, to the bit:
// one- and two-sided, linear and nonlinear, wo and wi on either side.
TEST(RoughPlasticLanes, RoughPlasticEvaluationsInLanesAreBsdfEvalPdfToTheBit) {
  Pcg32 rng(37);
  int zero = 0;
  for (int variant = 0; variant < 8; ++variant)
    zero += compareEvals<RoughPlasticLanes>(roughPlasticVariant(variant), rng, 503,
                                            "variant " + std::to_string(variant));
  EXPECT_GT(zero, 500) << "the directions below the surface were not reached";
  EXPECT_LT(zero, 3000);
}
