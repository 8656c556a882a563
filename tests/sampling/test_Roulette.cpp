// Russian roulette keeps the estimate unbiased whatever its survival scale, and the eta^2
// scale is exactly what refraction through a dielectric compressed.
#include <gtest/gtest.h>

#include "materials/Bsdf.h"
#include "sampling/Pcg32.h"
#include "sampling/Roulette.h"

using namespace envgi;

TEST(Roulette, UnbiasedForAnyScale) {
  for (float scale : {1.f, 2.25f, 0.3f}) {
    Pcg32 rng(11);
    const int n = 400000;
    double sum = 0.0;
    int survived = 0;
    for (int i = 0; i < n; ++i) {
      Color w(0.2f, 0.4f, 0.1f);
      if (russianRoulette(&w, rng.nextFloat(), kRouletteMaxSurvival, scale)) {
        sum += w.y;
        ++survived;
      }
    }
    double q = std::min(0.4 * scale, double(kRouletteMaxSurvival));
    EXPECT_NEAR(double(survived) / n, q, 0.005) << "scale " << scale;
    EXPECT_NEAR(sum / n, 0.4, 0.004) << "scale " << scale;
  }
  Color black(0.f);
  EXPECT_FALSE(russianRoulette(&black, 0.f, 1.f)) << "no throughput, no path";
}

TEST(Roulette, EtaSquaredOnlyForRefraction) {
  Bsdf glass;
  glass.type = BsdfType::Dielectric;
  glass.ior = 1.5f;
  Vec3f out(0.f, 0.f, 1.f), in(0.f, 0.f, -1.f);
  EXPECT_FLOAT_EQ(bsdfEtaSquared(glass, out, in), 2.25f) << "entering";
  EXPECT_FLOAT_EQ(bsdfEtaSquared(glass, in, out), 1.f / 2.25f) << "leaving";
  EXPECT_FLOAT_EQ(bsdfEtaSquared(glass, out, out), 1.f) << "reflection";
  // What the sampled weight of a refraction lost is what the scale gives back.
  BsdfSample bs;
  for (float uc = 0.f; uc < 1.f; uc += 0.01f)
    if (bsdfSample(glass, out, uc, Vec2f(0.5f, 0.5f), &bs) && bs.wi.z < 0.f) break;
  ASSERT_LT(bs.wi.z, 0.f);
  EXPECT_NEAR(bs.weight.x * bsdfEtaSquared(glass, out, bs.wi), 1.f, 1e-5f);
  Bsdf thin = glass;
  thin.type = BsdfType::ThinDielectric;
  EXPECT_FLOAT_EQ(bsdfEtaSquared(thin, out, in), 1.f) << "a thin sheet compresses nothing";
}
