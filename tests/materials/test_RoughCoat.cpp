// The rough plastic coat's tables (materials/RoughCoat.h): their smooth limit, their bounds,
// the roughness nodes a textured alpha reads, and the cache that keeps them.
#include <gtest/gtest.h>

#include <algorithm>

#include "materials/BsdfFactory.h"

using namespace envgi;

namespace {

CoatNode tableAt(float alpha, float ior, MicrofacetType type) {
  int nodes = 0;
  const float* t = roughCoatTable(alpha, ior, type, false, &nodes);
  EXPECT_EQ(nodes, 1);
  return coatNode(t, nodes, alpha);
}

}  // namespace

// Nearly smooth, the coat lets through 1 - F(mu), and its hemispherical terms are the smooth
// interface's (fresnelDiffuseReflectance, a separate midpoint rule): both quadratures, the
// visible-normal one (GGX) and the normal-distribution one (Beckmann), must find them.
TEST(RoughCoat, NearlySmoothCoatIsTheSmoothInterface) {
  const float ior = 1.49f;
  for (MicrofacetType type : {MicrofacetType::GGX, MicrofacetType::Beckmann}) {
    CoatNode n = tableAt(1e-3f, ior, type);
    for (float mu : {0.1f, 0.3f, 0.5f, 0.8f, 1.f})
      EXPECT_NEAR(coatTransmittance(n, mu), 1.f - fresnelDielectric(mu, ior), 2e-3f) << "mu " << mu;
    // Mitsuba's hemispherical terms are 2 mean(R mu) over the table's own nodes (a coarse
    // rule, 1.8% under the integral at this ior): the same rule over the smooth Fresnel.
    double fdr = 0.0, tHemi = 0.0;
    for (int i = 0; i < kCoatRes; ++i) {
      float mu = std::max(1e-6f, float(i) / float(kCoatRes - 1));
      fdr += fresnelDielectric(mu, 1.f / ior) * mu;
      tHemi += (1.f - fresnelDielectric(mu, ior)) * mu;
    }
    EXPECT_NEAR(coatInternalReflectance(n), 2.0 * fdr / kCoatRes, 2e-3);
    EXPECT_NEAR(coatDiffuseTransmittance(n), 2.0 * tHemi / kCoatRes, 2e-3);
    EXPECT_NEAR(coatInternalReflectance(n), fresnelDiffuseReflectance(1.f / ior), 0.02f);
  }
}

// Rougher coats let less through at normal incidence (light is masked on the way in) and keep
// every entry a fraction.
TEST(RoughCoat, EntriesAreFractionsAndRoughnessMasksLight) {
  for (MicrofacetType type : {MicrofacetType::GGX, MicrofacetType::Beckmann}) {
    float previous = 1.f;
    for (float alpha : {0.05f, 0.2f, 0.5f, 1.f}) {
      CoatNode n = tableAt(alpha, 1.5f, type);
      for (int i = 0; i < kCoatRes + 2; ++i) {
        EXPECT_GE(coatEntry(n, i), 0.f);
        EXPECT_LE(coatEntry(n, i), 1.f);
      }
      float t1 = coatTransmittance(n, 1.f);
      EXPECT_LT(t1, previous) << "alpha " << alpha;
      previous = t1;
    }
  }
}

// A textured alpha reads between the nodes of one table over all roughnesses: within 1% of the
// table made at that very roughness, in between nodes too.
TEST(RoughCoat, TexturedAlphaNodesFollowTheExactTables) {
  int nodes = 0;
  const float* all = roughCoatTable(0.f, 1.49f, MicrofacetType::GGX, true, &nodes);
  EXPECT_EQ(nodes, kCoatAlphaNodes);
  for (float alpha : {0.012f, 0.1f, 0.3f, 0.65f}) {
    CoatNode between = coatNode(all, nodes, alpha), exact = tableAt(alpha, 1.49f, MicrofacetType::GGX);
    for (float mu : {0.05f, 0.4f, 1.f})
      EXPECT_NEAR(coatTransmittance(between, mu), coatTransmittance(exact, mu), 0.01f) << alpha << " " << mu;
    EXPECT_NEAR(coatInternalReflectance(between), coatInternalReflectance(exact), 0.01f) << alpha;
  }
  // At a node itself, the node's own values.
  CoatNode atNode = coatNode(all, nodes, coatNodeAlpha(5, nodes));
  const float* fifth = all + 5 * kCoatStride;
  CoatNode own{fifth, fifth, 0.f};
  for (float mu : {0.05f, 0.5f, 1.f}) EXPECT_NEAR(coatTransmittance(atNode, mu), coatTransmittance(own, mu), 1e-5f);
}

// The tables are made once per key and live for the process: a Bsdf may point at them.
TEST(RoughCoat, TablesAreSharedAndAttachedToRoughPlasticOnly) {
  int n1 = 0, n2 = 0;
  EXPECT_EQ(roughCoatTable(0.2f, 1.5f, MicrofacetType::GGX, false, &n1),
            roughCoatTable(0.2f, 1.5f, MicrofacetType::GGX, false, &n2));
  EXPECT_NE(roughCoatTable(0.2f, 1.5f, MicrofacetType::GGX, false, &n1),
            roughCoatTable(0.2f, 1.5f, MicrofacetType::Beckmann, false, &n2));
  Bsdf b;
  b.type = BsdfType::RoughPlastic;
  b.alpha = 0.2f;
  b.ior = 1.5f;
  attachRoughCoat(b);
  EXPECT_EQ(bsdfCoatTable(b), roughCoatTable(0.2f, 1.5f, MicrofacetType::GGX, false, &n1));
  EXPECT_EQ(b.coatNodes, 1);
  b.alphaTexture = 0;
  attachRoughCoat(b);
  EXPECT_EQ(b.coatNodes, kCoatAlphaNodes);
  Bsdf d;
  attachRoughCoat(d);
  EXPECT_EQ(d.coatNodes, 0);
  EXPECT_EQ(bsdfCoatTable(d), nullptr);
}

// finishPlastic leaves the coat to attachRoughCoat: the loader calls it before the alpha's
// texture is known, where a table for the untextured alpha would be built for nothing.
TEST(RoughCoat, FinishPlasticLeavesTheTablesToAttach) {
  Bsdf b;
  b.type = BsdfType::RoughPlastic;
  b.alpha = 0.2f;
  b.ior = 1.5f;
  finishPlastic(b);
  EXPECT_GT(b.fdrInt, 0.f);
  EXPECT_EQ(b.coatNodes, 0);
  EXPECT_EQ(bsdfCoatTable(b), nullptr);
}
