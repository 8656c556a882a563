// Two BSDFs evaluated as their mix (1 - w) a + w b (materials/BsdfMix.h), as the path tracer
// does a one-level blend: the reweighted sample is the mix's value over the mix's density, its
// mean over the choice of a or b is the mix's albedo, and where a and b differ only in colour
// it has no variance left at all.
#include <gtest/gtest.h>

#include "materials/BsdfFactory.h"
#include "materials/BsdfMix.h"
#include "sampling/Pcg32.h"
#include "support/TestBsdfs.h"

using namespace envgi;
using test::diffuse;
using test::mirror;

namespace {

Bsdf roughPlastic(MicrofacetType dist) {
  Bsdf b;
  b.type = BsdfType::RoughPlastic;
  b.alpha = 0.15f;
  b.distribution = dist;
  b.reflectance = Color(0.6f, 0.08f, 0.05f);
  b.ior = 1.49f;
  finishPlastic(b);
  attachRoughCoat(b);
  return b;
}

Bsdf roughGold() {
  Bsdf b;
  b.type = BsdfType::RoughConductor;
  b.alpha = 0.08f;
  b.distribution = MicrofacetType::Beckmann;
  conductorPreset("Au", &b.eta, &b.k, &b.perfectMirror);
  return b;
}

// One sample of the mix: a or b with the chance of its weight, then reweighted by the other.
bool sampleMix(const Bsdf& a, const Bsdf& b, float wb, Vec3f wo, Pcg32& rng, BsdfSample* s) {
  const bool pickB = rng.nextFloat() < wb;
  const Bsdf& chosen = pickB ? b : a;
  if (!bsdfSample(chosen, wo, rng.nextFloat(), Vec2f(rng.nextFloat(), rng.nextFloat()), s)) return false;
  bsdfMixReweight(pickB ? a : b, pickB ? 1.f - wb : wb, wo, s);
  return true;
}

// The mean sample weight (a BSDF's albedo from wo), n samples.
template <class Draw>
Color meanWeight(Draw draw, int n) {
  Color sum(0.f);
  for (int i = 0; i < n; ++i) {
    BsdfSample s;
    if (draw(&s)) sum += s.weight;
  }
  return sum / float(n);
}

}  // namespace

TEST(BsdfMix, ReweightedSampleIsTheMixOverItsDensity) {
  const Bsdf a = roughPlastic(MicrofacetType::Beckmann), b = roughGold();
  const float wb = 0.3f;
  const Vec3f wo = normalize(Vec3f(0.4f, 0.1f, 0.8f));
  Pcg32 rng(7);
  int checked = 0;
  for (int i = 0; i < 2000; ++i) {
    BsdfSample s;
    if (!sampleMix(a, b, wb, wo, rng, &s) || s.delta) continue;
    float pdf;
    Color f = bsdfMixEvalPdf(a, &b, wb, wo, s.wi, &pdf);
    ASSERT_NEAR(s.pdf, pdf, 1e-3f * pdf);
    Color expect = f / pdf;
    ASSERT_LE(length(s.weight - expect), 1e-3f * fmaxf(1.f, length(expect))) << i;
    ++checked;
  }
  EXPECT_GT(checked, 1900);
}

// Unbiased: the mix's albedo is (1 - w) a's + w b's, each measured alone; with a delta lobe in
// one of them (a mirror) too.
TEST(BsdfMix, MeanWeightIsTheMixOfTheAlbedos) {
  const Vec3f wo = normalize(Vec3f(0.3f, -0.2f, 0.7f));
  const int n = 400000;
  struct Pair {
    Bsdf a, b;
    float wb;
  };
  for (const Pair& p : {Pair{roughPlastic(MicrofacetType::GGX), roughGold(), 0.3f}, Pair{diffuse(0.5f), mirror(), 0.4f}}) {
    Pcg32 rng(11);
    auto alone = [&](const Bsdf& x) {
      return meanWeight([&](BsdfSample* s) {
        return bsdfSample(x, wo, rng.nextFloat(), Vec2f(rng.nextFloat(), rng.nextFloat()), s);
      }, n);
    };
    Color expect = alone(p.a) * (1.f - p.wb) + alone(p.b) * p.wb;
    Color got = meanWeight([&](BsdfSample* s) { return sampleMix(p.a, p.b, p.wb, wo, rng, s); }, n);
    for (int c = 0; c < 3; ++c) EXPECT_NEAR(got[c], expect[c], 0.01f * expect[c] + 1e-3f) << "channel " << c;
  }
}

// Two diffuse materials: every sample of the mix weighs the mix's albedo, 0.75 x 0.2 + 0.25 x 0.8,
// where the choice alone gave 0.2 or 0.8.
TEST(BsdfMix, TwoDiffuseMaterialsLeaveNoVariance) {
  const Bsdf a = diffuse(0.2f), b = diffuse(0.8f);
  const Vec3f wo = normalize(Vec3f(0.2f, 0.3f, 0.9f));
  Pcg32 rng(3);
  for (int i = 0; i < 1000; ++i) {
    BsdfSample s;
    ASSERT_TRUE(sampleMix(a, b, 0.25f, wo, rng, &s));
    ASSERT_NEAR(s.weight.x, 0.35f, 1e-5f) << i;
  }
}

TEST(BsdfMix, NextEventSeesTheMixUnlessEveryLobeIsADelta) {
  const Bsdf d = diffuse(0.5f), m = mirror();
  EXPECT_TRUE(bsdfMixIsDelta(m, nullptr));
  EXPECT_TRUE(bsdfMixIsDelta(m, &m));
  EXPECT_FALSE(bsdfMixIsDelta(m, &d));
  EXPECT_FALSE(bsdfMixIsDelta(d, &m));
  // The mirror chosen, the diffuse partner at weight 0.6: a light sample sees 0.6 of its albedo.
  const Vec3f wo(0.f, 0.f, 1.f), wi = normalize(Vec3f(0.3f, 0.f, 1.f));
  float pdf;
  Color f = bsdfMixEvalPdf(m, &d, 0.6f, wo, wi, &pdf);
  EXPECT_NEAR(f.x, 0.6f * 0.5f * wi.z * kInvPi, 1e-6f);
  EXPECT_NEAR(pdf, 0.6f * wi.z * kInvPi, 1e-6f);
}
