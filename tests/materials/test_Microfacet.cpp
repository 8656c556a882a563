// Both microfacet distributions against their defining integrals, by quadrature over the
// sphere of normals (independent of the sampling code, which test_Bsdf's chi-square covers).
#include <gtest/gtest.h>

#include <cmath>

#include "materials/Microfacet.h"

namespace envgi {
namespace {

// Integral over the upper hemisphere of f(m), on a grid fine in theta near the pole, where a
// low alpha puts all of D.
template <class F>
double hemisphereQuadrature(F f, int nt = 2000, int np = 256) {
  double sum = 0.0;
  for (int i = 0; i < nt; ++i) {
    // theta = (pi / 2) s^2 crowds samples near the pole; dtheta = pi s ds.
    double s = (i + 0.5) / nt, theta = 0.5 * M_PI * s * s, dtheta = M_PI * s / nt;
    for (int j = 0; j < np; ++j) {
      double phi = 2.0 * M_PI * (j + 0.5) / np;
      Vec3f m(float(std::sin(theta) * std::cos(phi)), float(std::sin(theta) * std::sin(phi)), float(std::cos(theta)));
      sum += f(m) * std::sin(theta) * dtheta * (2.0 * M_PI / np);
    }
  }
  return sum;
}

// The normals' projected area is the surface's: the integral of D(m) cos(m) is 1. And Smith's
// lambda is the one that makes visible normals a density (integral of G1(w) (w.m)+ D(m) = cos
// w, i.e. visiblePdf integrates to 1), which a wrong lambda (say GGX's for Beckmann) breaks.
// Anisotropic pairs too, seen from an azimuth along neither axis.
TEST(Microfacet, NormalizedAndLambdaMatchesD) {
  const std::pair<float, float> alphas[] = {{0.05f, 0.05f}, {0.2f, 0.2f}, {0.6f, 0.6f}, {1.2f, 1.2f},
                                            {0.1f, 0.5f},   {0.6f, 0.15f}};
  for (MicrofacetType t : {MicrofacetType::GGX, MicrofacetType::Beckmann})
    for (auto [ax, ay] : alphas) {
      MicrofacetDistribution d{ax, ay, t};
      float alpha = ax + 0.001f * ay;  // for the messages
      double proj = hemisphereQuadrature([&](Vec3f m) { return d.D(m) * m.z; });
      EXPECT_NEAR(proj, 1.0, 2e-3) << "type " << int(t) << " alpha " << alpha;
      for (float c : {0.98f, 0.6f, 0.2f, 0.05f}) {
        Vec3f w(std::sqrt(1.f - c * c) * 0.8f, std::sqrt(1.f - c * c) * 0.6f, c);
        double vis = hemisphereQuadrature([&](Vec3f m) { return d.visiblePdf(w, m) * (dot(w, m) > 0.f); });
        EXPECT_NEAR(vis, 1.0, 3e-3) << "type " << int(t) << " alpha " << alpha << " cos " << c;
      }
    }
}

// Beckmann's D and lambda at known values: D(n) = 1 / (pi alpha^2), and lambda from the
// closed form (erfc(a) and e^-a^2 at a = 1 / (alpha tan theta)) evaluated in double.
TEST(Microfacet, BeckmannClosedForms) {
  MicrofacetDistribution d{0.3f, 0.3f, MicrofacetType::Beckmann};
  EXPECT_NEAR(d.D(Vec3f(0.f, 0.f, 1.f)), 1.0 / (M_PI * 0.09), 1e-4);
  for (double theta : {0.1, 0.7, 1.2, 1.5}) {
    Vec3f w(float(std::sin(theta)), 0.f, float(std::cos(theta)));
    double a = 1.0 / (0.3 * std::tan(theta));
    double expect = 0.5 * (std::exp(-a * a) / (a * std::sqrt(M_PI)) - std::erfc(a));
    EXPECT_NEAR(d.lambda(w), expect, 1e-6 + 1e-4 * expect) << theta;
  }
  EXPECT_EQ(d.lambda(Vec3f(0.f, 0.f, 1.f)), 0.f);
}

// Sampled normals stay finite and in the upper hemisphere, from every side and grazing angle.
TEST(Microfacet, SampledNormalsAreFiniteUnitUpperHemisphere) {
  for (MicrofacetType t : {MicrofacetType::GGX, MicrofacetType::Beckmann})
    for (float alpha : {1e-3f, 0.1f, 1.f, 4.f})
      for (float c : {1.f, 0.5f, 1e-4f, 0.f, -0.5f, -1.f})
        for (float u0 : {0.f, 1e-7f, 0.5f, 0.9999999f})
          for (float u1 : {0.f, 0.25f, 0.9999999f}) {
            Vec3f w(std::sqrt(fmaxf(0.f, 1.f - c * c)), 0.f, c);
            Vec3f m = MicrofacetDistribution{alpha, alpha, t}.sampleVisible(w, Vec2f(u0, u1));
            ASSERT_TRUE(std::isfinite(m.x) && std::isfinite(m.y) && std::isfinite(m.z));
            ASSERT_GT(m.z, 0.f);
            ASSERT_NEAR(length(m), 1.f, 1e-5f);
          }
}

}  // namespace
}  // namespace envgi
