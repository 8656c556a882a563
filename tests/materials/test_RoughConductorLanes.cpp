// RoughConductorLanes, rough conductor's batch forms: its samples and its evaluations in lanes
// are bsdfSample's and bsdfEvalPdf's, to the bit, or fail where they fail.
#include <gtest/gtest.h>

#include "support/BsdfLanesChecks.h"
#include "materials/RoughConductorLanes.h"

using namespace envgi;

namespace {

// Eight rough conductors: four roughnesses, one- and two-sided, a metal's Fresnel and a
// perfect mirror's.
Bsdf roughConductorVariant(int variant) {
  Bsdf b;
  b.type = BsdfType::RoughConductor;
  b.distribution = MicrofacetType::GGX;
  b.alpha = variant % 4 == 0 ? 0.01f : (variant % 4 == 1 ? 0.1f : (variant % 4 == 2 ? 0.4f : 1.3f));
  b.twoSided = variant % 2 == 0;
  b.perfectMirror = variant >= 6;
  b.eta = Color(0.2f, 0.92f, 1.1f);  // copper's
  b.k = Color(3.9f, 2.45f, 2.14f);
  b.specularReflectance = variant < 4 ? Color(1.f) : Color(0.9f, 0.8f, 0.6f);
  return b;
}

}  // namespace

TEST(RoughConductorLanes, SamplesInLanesAreBsdfSampleToTheBit) {
  Pcg32 rng(41);
  int none = 0, sampled = 0;
  for (int variant = 0; variant < 8; ++variant)
    none += compareSamples<RoughConductorLanes>(roughConductorVariant(variant), rng, 601,
                                                "variant " + std::to_string(variant),
                                                [&](const RoughConductorLanes&, int) { ++sampled; });
  EXPECT_EQ(none + sampled, 8 * 601);
  // The failures' cases reached: a wo below a one-sided surface, a direction mirrored below it.
  EXPECT_GT(none, 300);
  EXPECT_LT(none, 3000);
}

TEST(RoughConductorLanes, EvaluationsInLanesAreBsdfEvalPdfToTheBit) {
  Pcg32 rng(43);
  int zero = 0;
  for (int variant = 0; variant < 8; ++variant)
    zero += compareEvals<RoughConductorLanes>(roughConductorVariant(variant), rng, 503,
                                              "variant " + std::to_string(variant));
  EXPECT_GT(zero, 500) << "the directions below the surface were not reached";
  EXPECT_LT(zero, 3000);
}
