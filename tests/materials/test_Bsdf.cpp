// Chi-square tests of every BSDF's sample() against its pdf() at several roughnesses and
// incident angles, plus weight = eval/pdf, reciprocity, non-negativity and energy bounds.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <string>

#include "materials/BsdfFactory.h"
#include "sampling/Pcg32.h"
#include "support/ChiSquare.h"

using namespace envgi;

namespace {

struct BsdfCase {
  std::string name;
  Bsdf bsdf;
  float cosTheta;  // of wo; negative = from inside / below
};

Bsdf make(BsdfType t, float alpha, const char* metal = "none", MicrofacetType dist = MicrofacetType::GGX) {
  Bsdf b;
  b.type = t;
  b.alpha = alpha;
  b.distribution = dist;
  b.reflectance = Color(0.7f, 0.5f, 0.3f);
  if (t == BsdfType::Conductor || t == BsdfType::RoughConductor) conductorPreset(metal, &b.eta, &b.k, &b.perfectMirror);
  if (t == BsdfType::Plastic || t == BsdfType::RoughPlastic) {
    b.ior = 1.49f;
    // Its Fresnel terms only: the rough coat's tables (0.2 s of CPU, most of a test process's
    // start) come from coated() in the test that reads them, not from gtest's registration.
    finishPlastic(b);
  }
  return b;
}

Bsdf coated(Bsdf b) {
  attachRoughCoat(b);
  return b;
}

std::vector<BsdfCase> cases() {
  std::vector<BsdfCase> out;
  for (float c : {0.95f, 0.5f, 0.15f}) {
    std::string cs = std::to_string(int(c * 100));
    out.push_back({"Diffuse" + cs, make(BsdfType::Diffuse, 0.1f), c});
    out.push_back({"Plastic" + cs, make(BsdfType::Plastic, 0.1f), c});
    for (float a : {0.1f, 0.3f, 0.7f}) {
      std::string as = std::to_string(int(a * 10));
      out.push_back({"RoughConductorAu" + cs + "a" + as, make(BsdfType::RoughConductor, a, "Au"), c});
      out.push_back({"RoughPlastic" + cs + "a" + as, make(BsdfType::RoughPlastic, a), c});
      out.push_back({"RoughDielectric" + cs + "a" + as, make(BsdfType::RoughDielectric, a), c});
      out.push_back({"RoughDielectricInside" + cs + "a" + as, make(BsdfType::RoughDielectric, a), -c});
      const MicrofacetType beck = MicrofacetType::Beckmann;
      out.push_back({"BeckmannConductorAu" + cs + "a" + as, make(BsdfType::RoughConductor, a, "Au", beck), c});
      out.push_back({"BeckmannPlastic" + cs + "a" + as, make(BsdfType::RoughPlastic, a, "none", beck), c});
      out.push_back({"BeckmannDielectric" + cs + "a" + as, make(BsdfType::RoughDielectric, a, "none", beck), c});
      out.push_back({"BeckmannDielectricInside" + cs + "a" + as, make(BsdfType::RoughDielectric, a, "none", beck), -c});
    }
    // Anisotropic: alpha 0.08 along s, 0.4 along t (Mitsuba's alpha_u, alpha_v).
    for (MicrofacetType dist : {MicrofacetType::GGX, MicrofacetType::Beckmann}) {
      std::string ds = dist == MicrofacetType::GGX ? "Ggx" : "Beckmann";
      auto aniso = [&](BsdfType t, const char* metal) {
        Bsdf b = make(t, 0.08f, metal, dist);
        b.alphaV = 0.4f;
        return b;
      };
      out.push_back({"Aniso" + ds + "ConductorAu" + cs, aniso(BsdfType::RoughConductor, "Au"), c});
      out.push_back({"Aniso" + ds + "Dielectric" + cs, aniso(BsdfType::RoughDielectric, "none"), c});
      out.push_back({"Aniso" + ds + "DielectricInside" + cs, aniso(BsdfType::RoughDielectric, "none"), -c});
    }
  }
  Bsdf two = make(BsdfType::Diffuse, 0.1f);
  two.twoSided = true;
  out.push_back({"TwoSidedDiffuseBack", two, -0.6f});
  // A rough plastic whose alpha is textured reads its coat between roughness nodes; seen from
  // behind as a two-sided one; and nonlinear (its tables over all roughnesses take 0.3 s).
  Bsdf textured = make(BsdfType::RoughPlastic, 0.25f);
  textured.alphaTexture = 0;
  textured.twoSided = true;
  textured.nonlinear = true;
  out.push_back({"RoughPlasticTexturedAlphaBack", textured, -0.4f});
  // Under a normal map (Mitsuba's normalmap, with its defaults: the flip and the shadowing
  // term): the lobes in the tilted frame, cut where a direction lies on different sides of the
  // two frames. The tilt is about y, the histogram's pole, by six of its 64 columns, so that both
  // horizons run along cell edges: a cut across a cell leaves slivers its midpoints can miss.
  auto mapped = [&](Bsdf b) {
    b.normalMapTexture = 0;
    const float tilt = 6.f * 2.f * kPi / 64.f;
    b.mappedNormal = Vec3f(std::sin(tilt), 0.f, std::cos(tilt));
    return b;
  };
  for (float c : {0.9f, 0.3f}) {
    std::string cs = std::to_string(int(c * 100));
    out.push_back({"NormalMappedDiffuse" + cs, mapped(make(BsdfType::Diffuse, 0.1f)), c});
    out.push_back({"NormalMappedRoughPlastic" + cs, mapped(make(BsdfType::RoughPlastic, 0.2f)), c});
    out.push_back({"NormalMappedRoughDielectric" + cs, mapped(make(BsdfType::RoughDielectric, 0.3f)), c});
    out.push_back({"NormalMappedRoughDielectricInside" + cs, mapped(make(BsdfType::RoughDielectric, 0.3f)), -c});
  }
  // Mitsuba's principled: its lobes apart and together (roughness 0.5 is alpha 0.25).
  auto principled = [&](auto set) {
    Bsdf b = make(BsdfType::Principled, 0.1f);
    b.ior = 1.5f;
    set(b.principled);
    return b;
  };
  for (float c : {0.9f, 0.3f}) {
    std::string cs = std::to_string(int(c * 100));
    out.push_back({"PrincipledBase" + cs, principled([](PrincipledParams&) {}), c});
    out.push_back({"PrincipledMetalAniso" + cs, principled([](PrincipledParams& p) {
                     p.metallic = 1.f, p.roughness = 0.4f, p.anisotropic = 0.6f;
                   }), c});
    out.push_back({"PrincipledClearcoat" + cs, principled([](PrincipledParams& p) {
                     p.clearcoat = 1.f, p.clearcoatGloss = 0.2f, p.roughness = 0.6f, p.sheen = 1.f;
                   }), c});
    for (float side : {1.f, -1.f})
      out.push_back({std::string(side > 0 ? "PrincipledGlass" : "PrincipledGlassInside") + cs,
                     principled([](PrincipledParams& p) { p.specTrans = 1.f; }), side * c});
    out.push_back({"PrincipledEverything" + cs, principled([](PrincipledParams& p) {
                     p.metallic = 0.3f, p.specTrans = 0.4f, p.roughness = 0.45f, p.clearcoat = 0.5f, p.sheen = 0.5f;
                     p.flatness = 0.5f, p.specTint = 0.3f, p.anisotropic = 0.3f;
                     p.specularRate = 0.7f, p.clearcoatRate = 1.3f, p.diffuseRate = 1.1f;
                   }), c});
  }
  Bsdf twoMapped = mapped(make(BsdfType::RoughConductor, 0.2f, "Cu"));
  twoMapped.twoSided = true;
  out.push_back({"NormalMappedTwoSidedConductorBack", twoMapped, -0.5f});
  return out;
}

Vec3f woFor(float c) { return normalize(Vec3f(safeSqrt(1.f - c * c), 0.1f * (c > 0 ? 1.f : -1.f), c)); }

void PrintTo(const BsdfCase& c, std::ostream* os) { *os << c.name; }

class BsdfChi2 : public ::testing::TestWithParam<BsdfCase> {};

// The chi-square test of bsdfSample against bsdfPdf, the lobe picked by uc or (lobeFromU) by u.x.
void expectSampleMatchesPdf(BsdfCase c, bool lobeFromU) {
  attachRoughCoat(c.bsdf);
  Vec3f wo = woFor(c.cosTheta);
  Pcg32 rng(123);
  const int n = 200000;
  int badWeight = 0;
  auto sample = [&](int) {
    BsdfSample s;
    float uc = rng.nextFloat();
    Vec2f u(rng.nextFloat(), rng.nextFloat());
    if (!bsdfSample(c.bsdf, wo, uc, u, &s, lobeFromU) || s.delta)
      return Vec3f(0.f);  // delta or failed samples count as missing mass
    Color expect = bsdfEval(c.bsdf, wo, s.wi) / s.pdf;
    if (length(expect - s.weight) > 1e-3f * fmaxf(1.f, length(expect))) ++badWeight;
    if (std::fabs(bsdfPdf(c.bsdf, wo, s.wi) - s.pdf) > 1e-3f * s.pdf) ++badWeight;
    // The horizon lies on histogram cell edges; a sample within rounding of it may land on the
    // wrong side, so the thin band is left out (its mass is ~1e-4 of the total).
    if (std::fabs(s.wi.z) < 1e-4f) return Vec3f(0.f);
    return s.wi;
  };
  auto pdf = [&](Vec3f wi) { return bsdfPdf(c.bsdf, wo, wi); };
  test::ChiSquareResult r = test::chiSquareSphere(sample, pdf, n, 64, 32, 16);
  EXPECT_EQ(badWeight, 0);
  EXPECT_LE(r.pdfIntegral, 1.0 + 2e-2);
  EXPECT_GT(r.pValue, test::sidakAlpha(int(cases().size()))) << "chi2 " << r.chi2 << " dof " << r.dof << " " << r.message;
}

TEST_P(BsdfChi2, SampleMatchesPdf) { expectSampleMatchesPdf(GetParam(), false); }

INSTANTIATE_TEST_SUITE_P(All, BsdfChi2, ::testing::ValuesIn(cases()),
                         [](const ::testing::TestParamInfo<BsdfCase>& i) { return i.param.name; });

// The same with the lobe picked by u.x, for the BSDFs that can (bsdfLobeFromU: plastics and
// principled): the density drawn must stay bsdfPdf's.
class BsdfChi2LobeFromU : public ::testing::TestWithParam<BsdfCase> {};
TEST_P(BsdfChi2LobeFromU, SampleMatchesPdf) { expectSampleMatchesPdf(GetParam(), true); }

std::vector<BsdfCase> lobeFromUCases() {
  std::vector<BsdfCase> out;
  for (const BsdfCase& c : cases())
    if (bsdfLobeFromU(c.bsdf)) out.push_back(c);
  return out;
}
INSTANTIATE_TEST_SUITE_P(LobesFromU, BsdfChi2LobeFromU, ::testing::ValuesIn(lobeFromUCases()),
                         [](const ::testing::TestParamInfo<BsdfCase>& i) { return i.param.name; });

// With the lobe from u.x, a draw is the two-draw form's with uc = u.x and u.x stretched over the
// chosen lobe's share: the coat below the share ps, the base above it.
TEST(Bsdf, LobeFromUIsTheTwoDrawFormWithUcFromUx) {
  Pcg32 rng(41);
  for (BsdfType t : {BsdfType::Plastic, BsdfType::RoughPlastic}) {
    for (bool twoSided : {false, true}) {
      Bsdf b = coated(make(t, 0.2f));
      b.twoSided = twoSided;
      ASSERT_TRUE(bsdfLobeFromU(b));
      ASSERT_FALSE(bsdfReadsUcBesideU(b));
      int coat = 0, base = 0;
      for (int i = 0; i < 4000; ++i) {
        Vec3f wo = sampleUniformSphere({rng.nextFloat(), rng.nextFloat()});
        Vec2f u(rng.nextFloat(), rng.nextFloat());
        float c = twoSided ? std::fabs(wo.z) : wo.z;
        if (c <= 0.f) continue;
        float fo = t == BsdfType::Plastic ? fresnelDielectric(c, b.ior)
                                          : detail::roughCoatReflectance(b, detail::roughCoat(b), c);
        float ps = detail::plasticSpecularProb(b, fo);
        Vec2f stretched(u.x < ps ? stretchedDraw(u.x, 0.f, ps) : stretchedDraw(u.x, ps, 1.f - ps), u.y);
        (u.x < ps ? coat : base)++;
        BsdfSample a, e;
        bool okA = bsdfSample(b, wo, rng.nextFloat(), u, &a, true), okE = bsdfSample(b, wo, u.x, stretched, &e);
        ASSERT_EQ(okA, okE);
        if (!okA) continue;
        ASSERT_EQ(a.delta, e.delta);
        ASSERT_EQ(a.pdf, e.pdf);
        ASSERT_EQ(a.wi.x, e.wi.x);
        ASSERT_EQ(a.wi.y, e.wi.y);
        ASSERT_EQ(a.wi.z, e.wi.z);
        ASSERT_EQ(a.weight.y, e.weight.y);
      }
      EXPECT_GT(coat, 100) << int(t);  // both lobes were drawn
      EXPECT_GT(base, 100) << int(t);
    }
  }
}

// Hence a regular n x n grid of u splits between smooth plastic's lobes as the coat's share
// says, to within one column; a separate uc splits it so only in expectation.
TEST(Bsdf, LobeFromUSplitsAGridAsTheCoatsShare) {
  Bsdf b = coated(make(BsdfType::Plastic, 0.2f));
  for (float c : {0.95f, 0.5f, 0.15f}) {
    const Vec3f wo = woFor(c);
    const int n = 64;
    int coat = 0;
    for (int i = 0; i < n; ++i)
      for (int j = 0; j < n; ++j) {
        BsdfSample s;
        if (bsdfSample(b, wo, 0.5f, Vec2f((i + 0.5f) / n, (j + 0.5f) / n), &s, true)) coat += s.delta;
      }
    EXPECT_NEAR(double(coat) / (n * n), bsdfDeltaProb(b, wo), 1.0 / n) << c;
  }
}

TEST(Bsdf, NonNegativeAndReciprocal) {
  Pcg32 rng(5);
  const MicrofacetType ggx = MicrofacetType::GGX, beck = MicrofacetType::Beckmann;
  const std::pair<BsdfType, MicrofacetType> kinds[] = {
      {BsdfType::Diffuse, ggx},         {BsdfType::RoughConductor, ggx}, {BsdfType::RoughPlastic, ggx},
      {BsdfType::Plastic, ggx},         {BsdfType::RoughDielectric, ggx}, {BsdfType::RoughConductor, beck},
      {BsdfType::RoughPlastic, beck},   {BsdfType::RoughDielectric, beck}};
  for (auto [t, dist] : kinds) {
    Bsdf b = coated(make(t, 0.3f, "Cu", dist));
    for (int i = 0; i < 2000; ++i) {
      Vec3f a = sampleUniformSphere({rng.nextFloat(), rng.nextFloat()});
      Vec3f c = sampleUniformSphere({rng.nextFloat(), rng.nextFloat()});
      Color f1 = bsdfEval(b, a, c), f2 = bsdfEval(b, c, a);
      ASSERT_GE(f1.x, 0.f);
      ASSERT_GE(f1.y, 0.f);
      ASSERT_GE(f1.z, 0.f);
      ASSERT_GE(bsdfPdf(b, a, c), 0.f);
      // Reflection is reciprocal: f(a, c) = f(c, a) once the cosine of eval() is divided out.
      if (a.z * c.z > 0.f && std::fabs(a.z) > 0.05f && std::fabs(c.z) > 0.05f) {
        Color g1 = f1 / std::fabs(c.z), g2 = f2 / std::fabs(a.z);
        ASSERT_NEAR(g1.x, g2.x, 1e-3f * fmaxf(1.f, g1.x)) << int(t);
      }
    }
  }
}

// bsdfEvalPdf gives bsdfEval's and bsdfPdf's values to the bit, for every type and for
// directions on either side (two-sided rough plastic seen from behind included).
TEST(Bsdf, EvalPdfTogetherEqualsApart) {
  Pcg32 rng(23);
  for (const BsdfCase& c : cases()) {
    for (bool twoSided : {false, true}) {
      Bsdf b = coated(c.bsdf);
      b.twoSided = twoSided;
      for (int i = 0; i < 4000; ++i) {
        Vec3f wo = sampleUniformSphere({rng.nextFloat(), rng.nextFloat()});
        Vec3f wi = sampleUniformSphere({rng.nextFloat(), rng.nextFloat()});
        if (i % 4 == 0) wi = Vec3f(-wo.x, -wo.y, wo.z);  // the mirror direction: the specular peak
        float pdf = -1.f;
        Color f = bsdfEvalPdf(b, wo, wi, &pdf), fe = bsdfEval(b, wo, wi);
        ASSERT_EQ(pdf, bsdfPdf(b, wo, wi)) << c.name;
        ASSERT_EQ(f.x, fe.x) << c.name;
        ASSERT_EQ(f.y, fe.y) << c.name;
        ASSERT_EQ(f.z, fe.z) << c.name;
      }
    }
  }
}

// The integrators skip the lobe choice's draw where bsdfPicksALobe says a BSDF has one lobe:
// there bsdfSample must not depend on uc at all, and where it says two, it must.
TEST(Bsdf, OnlyTwoLobeBsdfsReadTheLobeChoice) {
  Pcg32 rng(31);
  std::vector<BsdfCase> all = cases();  // and the delta BSDFs, which the chi-square cases leave out
  all.push_back({"ConductorAu", make(BsdfType::Conductor, 0.1f, "Au"), 1.f});
  all.push_back({"Mirror", make(BsdfType::Conductor, 0.1f, "none"), 1.f});
  for (BsdfType t : {BsdfType::Dielectric, BsdfType::ThinDielectric}) {
    Bsdf glass = make(t, 0.1f);
    glass.ior = 1.5f;
    all.push_back({t == BsdfType::Dielectric ? "Dielectric" : "ThinDielectric", glass, 1.f});
  }
  // The integrators ask for the lobe from u.x (lobeFromU), and skip uc where
  // bsdfReadsUcBesideU says it goes unread then.
  for (bool lobeFromU : {false, true}) {
    for (BsdfCase& c : all) {
      c.bsdf = coated(c.bsdf);
      const bool reads = lobeFromU ? bsdfReadsUcBesideU(c.bsdf) : bsdfPicksALobe(c.bsdf);
      bool differs = false;
      for (int i = 0; i < 2000; ++i) {
        Vec3f wo = sampleUniformSphere({rng.nextFloat(), rng.nextFloat()});
        Vec2f u(rng.nextFloat(), rng.nextFloat());
        BsdfSample a, b;
        bool okA = bsdfSample(c.bsdf, wo, 0.02f, u, &a, lobeFromU), okB = bsdfSample(c.bsdf, wo, 0.98f, u, &b, lobeFromU);
        bool same = okA == okB && (!okA || (a.wi.x == b.wi.x && a.wi.y == b.wi.y && a.wi.z == b.wi.z &&
                                            a.weight.x == b.weight.x && a.pdf == b.pdf && a.delta == b.delta));
        differs = differs || !same;
        if (!reads) {
          ASSERT_TRUE(same) << c.name << " read uc" << (lobeFromU ? " (lobe from u)" : "");
        }
      }
      EXPECT_EQ(differs, reads) << c.name << (lobeFromU ? " (lobe from u)" : "");
    }
  }
}

// Integral of eval() over the sphere by quadrature (independent of the sampling code).
double hemisphereIntegral(const Bsdf& b, Vec3f wo) {
  const int n = 600;
  double sum = 0.0;
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < 2 * n; ++j) {
      float z = -1.f + 2.f * (i + 0.5f) / n, phi = kPi * (j + 0.5f) / n, r = safeSqrt(1.f - z * z);
      sum += bsdfEval(b, wo, Vec3f(r * std::cos(phi), r * std::sin(phi), z)).y;
    }
  return sum * (4.0 * M_PI) / (2.0 * n * n);
}

// Albedo = E[weight]: white conductors and dielectrics lose nothing when smooth and never
// create energy when rough.
TEST(Bsdf, EnergyConservation) {
  auto albedo = [](const Bsdf& b, Vec3f wo) {
    Pcg32 rng(17);
    double sum = 0.0;
    const int n = 100000;
    for (int i = 0; i < n; ++i) {
      BsdfSample s;
      if (bsdfSample(b, wo, rng.nextFloat(), Vec2f(rng.nextFloat(), rng.nextFloat()), &s)) sum += s.weight.y;
    }
    return sum / n;
  };
  for (float c : {0.9f, 0.4f, 0.1f}) {
    Vec3f wo = woFor(c);
    EXPECT_NEAR(albedo(make(BsdfType::Conductor, 0.1f), wo), 1.0, 1e-6);
    // Smooth glass: reflected + refracted energy is 1 once the 1/eta^2 radiance scaling is undone.
    for (float side : {1.f, -1.f}) {
      Bsdf g = make(BsdfType::Dielectric, 0.1f);
      Vec3f w = Vec3f(wo.x, wo.y, wo.z * side);
      Pcg32 rng(3);
      double e = 0.0;
      for (int i = 0; i < 20000; ++i) {
        BsdfSample s;
        ASSERT_TRUE(bsdfSample(g, w, rng.nextFloat(), Vec2f(rng.nextFloat(), rng.nextFloat()), &s));
        float etap = w.z > 0.f ? g.ior : 1.f / g.ior;
        e += s.wi.z * w.z < 0.f ? s.weight.y * etap * etap : s.weight.y;
      }
      EXPECT_NEAR(e / 20000, 1.0, 1e-5);
    }
    Bsdf thin = make(BsdfType::ThinDielectric, 0.1f);
    EXPECT_NEAR(albedo(thin, wo), 1.0, 1e-6);
    for (MicrofacetType dist : {MicrofacetType::GGX, MicrofacetType::Beckmann})
      for (float a : {0.05f, 0.3f, 0.8f}) {
        // Sampled albedo (mean weight) against a quadrature of eval(): single-scattering
        // microfacets lose energy (GGX at alpha = 1 up to half), never gain it.
        Bsdf rcb = make(BsdfType::RoughConductor, a, "none", dist);
        double rc = albedo(rcb, wo), quad = hemisphereIntegral(rcb, wo);
        EXPECT_LE(rc, 1.0 + 0.01) << "alpha " << a;
        EXPECT_NEAR(rc, quad, 0.01 + 0.01 * quad) << "alpha " << a << " cos " << c << " dist " << int(dist);
        EXPECT_LE(albedo(coated(make(BsdfType::RoughPlastic, a, "none", dist)), wo), 1.0 + 0.02);
        Bsdf rd = make(BsdfType::RoughDielectric, a, "none", dist);
        rd.ior = 1.f + 1e-4f;  // index-matched: transmission weight is not scaled
        EXPECT_LE(albedo(rd, wo), 1.0 + 0.01);
      }
    Bsdf d = make(BsdfType::Diffuse, 0.1f);
    d.reflectance = Color(1.f);
    EXPECT_NEAR(albedo(d, wo), 1.0, 1e-5);
  }
}

// Every material name Mitsuba 3's conductor takes (its spectra, as RGB in scalar_rgb): each
// gives finite, non-negative eta and k and a reflectance at normal incidence in (0, 1]; the
// "_palik" names read the same data as the plain ones, except Cu's, which Mitsuba keeps apart;
// tungsten (W) matches Mitsuba 3.9.1's RGB to 1e-3.
TEST(Bsdf, EveryMitsubaConductorMaterial) {
  const char* names[] = {"a-C",  "Ag",   "Al",  "AlAs", "AlSb", "Au",       "Be",  "Cr",  "CsI",      "Cu",
                         "Cu2O", "CuO",  "d-C", "Hg",   "HgTe", "Ir",       "K",   "Li",  "MgO",      "Mo",
                         "Nb",   "Rh",   "Se",  "SiC",  "SnTe", "Ta",       "Te",  "ThF4", "TiC",     "TiN",
                         "TiO2", "VC",   "VN",  "W",    "Na_palik", "Ni_palik", "V_palik", "Cu_palik"};
  for (const char* m : names) {
    Color eta, k;
    bool mirror = true;
    ASSERT_NO_THROW(conductorPreset(m, &eta, &k, &mirror)) << m;
    EXPECT_FALSE(mirror) << m;
    for (int c = 0; c < 3; ++c) {
      EXPECT_TRUE(std::isfinite(eta[c]) && eta[c] >= 0.f && std::isfinite(k[c]) && k[c] >= 0.f) << m;
    }
    const Color F = fresnelConductor(1.f, eta, k);
    EXPECT_GT(F.x + F.y + F.z, 0.f) << m;
    EXPECT_LE(std::max({F.x, F.y, F.z}), 1.f) << m;
  }
  for (const char* m : {"AlAs", "Be", "Hg", "Mo", "TiN", "VN"}) {
    Color eta, k, etaP, kP;
    bool mirror;
    conductorPreset(m, &eta, &k, &mirror);
    conductorPreset(std::string(m) + "_palik", &etaP, &kP, &mirror);
    EXPECT_EQ(eta.x, etaP.x) << m;
    EXPECT_EQ(k.z, kP.z) << m;
  }
  Color eta, k, etaP, kP;
  bool mirror;
  conductorPreset("Cu", &eta, &k, &mirror);
  conductorPreset("Cu_palik", &etaP, &kP, &mirror);
  EXPECT_NE(eta.x, etaP.x) << "Mitsuba's Cu and Cu_palik are two data sets";
  EXPECT_THROW(conductorPreset("Au_palik", &eta, &k, &mirror), std::runtime_error) << "Mitsuba has no Au_palik";
  conductorPreset("W", &eta, &k, &mirror);
  EXPECT_NEAR(eta.x, 4.371f, 1e-3f);
  EXPECT_NEAR(k.z, 2.273f, 1e-3f);
}

TEST(Bsdf, ConductorPresetsAndFresnel) {
  Color eta, k;
  bool mirror;
  for (const char* m : {"Au", "Ag", "Cu", "Al", "Cr"}) {
    conductorPreset(m, &eta, &k, &mirror);
    EXPECT_FALSE(mirror);
    Color F = fresnelConductor(1.f, eta, k);
    EXPECT_GT(F.x, 0.4f) << m;
    EXPECT_LE(F.x, 1.f);
  }
  conductorPreset("Au", &eta, &k, &mirror);
  Color F = fresnelConductor(1.f, eta, k);
  EXPECT_GT(F.x, F.z) << "gold reflects red more than blue";
  EXPECT_THROW(conductorPreset("Unobtainium", &eta, &k, &mirror), std::runtime_error);
  try {
    conductorPreset("Wolfram", &eta, &k, &mirror);
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("Ni_palik"), std::string::npos) << "the error lists the names: " << e.what();
  }
  EXPECT_NEAR(fresnelDielectric(1.f, 1.5f), 0.04f, 1e-4f);
  EXPECT_EQ(fresnelDielectric(-0.1f, 1.5f), 1.f);  // total internal reflection from inside
  EXPECT_NEAR(fresnelDiffuseReflectance(1.5f), 0.092f, 0.003f);
}

}  // namespace

// A normal map whose normal is the frame's own z leaves every BSDF as it was, to the bit: the
// tilted frame is then the frame itself and the shadowing term is 1.
TEST(Bsdf, NormalMapAlongZIsNoMap) {
  Pcg32 rng(41);
  for (const BsdfCase& c : cases()) {
    if (bsdfIsNormalMapped(c.bsdf)) continue;
    Bsdf m = c.bsdf;
    m.normalMapTexture = 0;
    attachRoughCoat(m);
    Bsdf plain = m;
    plain.normalMapTexture = -1;
    for (int i = 0; i < 500; ++i) {
      Vec3f wo = sampleUniformSphere({rng.nextFloat(), rng.nextFloat()});
      Vec3f wi = sampleUniformSphere({rng.nextFloat(), rng.nextFloat()});
      Color a = bsdfEval(m, wo, wi), b = bsdfEval(plain, wo, wi);
      ASSERT_EQ(a.x, b.x) << c.name;
      ASSERT_EQ(a.z, b.z) << c.name;
      ASSERT_EQ(bsdfPdf(m, wo, wi), bsdfPdf(plain, wo, wi)) << c.name;
      BsdfSample sm, sp;
      float uc = rng.nextFloat();
      Vec2f u(rng.nextFloat(), rng.nextFloat());
      bool okM = bsdfSample(m, wo, uc, u, &sm), okP = bsdfSample(plain, wo, uc, u, &sp);
      ASSERT_EQ(okM, okP) << c.name;
      if (okM) {
        ASSERT_EQ(sm.wi.z, sp.wi.z) << c.name;
        ASSERT_EQ(sm.weight.y, sp.weight.y) << c.name;
      }
    }
  }
}

// A Lambertian surface whose normal map tilts its normal by theta, under light from the whole
// upper hemisphere: the tilted cosine, cut at the surface, integrates to (1 + cos theta) / 2 of
// the albedo (the sky a tilted plane sees). With Mitsuba's shadowing term on, less: the term is
// at most 1 and falls towards the horizon. Pointwise, the value is the tilted cosine times it.
TEST(Bsdf, NormalMappedDiffuseIsTheTiltedCosine) {
  for (float tilt : {0.3f, 0.8f, 1.2f}) {
    Bsdf b = make(BsdfType::Diffuse, 0.1f);
    b.normalMapTexture = 0;
    b.mappedNormal = Vec3f(std::sin(tilt), 0.f, std::cos(tilt));
    b.bumpShadowing = false;
    Vec3f wo = normalize(Vec3f(0.2f, 0.1f, 1.f));  // sees the tilted normal's side: no flip
    double expect = b.reflectance.y * (1.0 + std::cos(tilt)) / 2.0;
    EXPECT_NEAR(hemisphereIntegral(b, wo), expect, 2e-3) << "tilt " << tilt;
    b.bumpShadowing = true;
    double shadowed = hemisphereIntegral(b, wo);
    EXPECT_LT(shadowed, expect - 1e-3) << "tilt " << tilt;
    EXPECT_GT(shadowed, 0.5 * expect) << "tilt " << tilt;
    Pcg32 rng(5);
    for (int i = 0; i < 1000; ++i) {
      Vec3f wi = sampleUniformSphere({rng.nextFloat(), rng.nextFloat()});
      float cosT = dot(wi, b.mappedNormal);
      float want = wi.z > 0.f && cosT > 0.f ? b.reflectance.y * kInvPi * cosT * detail::bumpShadowingTerm(b.mappedNormal, wi) : 0.f;
      ASSERT_NEAR(bsdfEval(b, wo, wi).y, want, 1e-6f);
    }
  }
}

// Mitsuba's flip_invalid_normals: a viewer on the far side of the tilted normal (wo below its
// plane, above the surface's) sees the normal mirrored about z, so the surface is not black there.
TEST(Bsdf, NormalMapFlipsANormalTheViewerCannotSee) {
  Bsdf b = make(BsdfType::Diffuse, 0.1f);
  b.normalMapTexture = 0;
  b.mappedNormal = normalize(Vec3f(0.9f, 0.f, 0.3f));
  Vec3f wo = normalize(Vec3f(-0.9f, 0.f, 0.2f));  // above the surface, behind the tilted plane
  ASSERT_LT(dot(wo, b.mappedNormal), 0.f);
  EXPECT_GT(hemisphereIntegral(b, wo), 0.1);
  b.flipInvalidNormals = false;
  EXPECT_EQ(hemisphereIntegral(b, wo), 0.0) << "the unflipped frame has wo below it";
}
