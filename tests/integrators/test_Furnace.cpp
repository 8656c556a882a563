// White furnace tests: under a constant environment of radiance 1, a convex object reflects
// exactly its albedo (diffuse), or all the light (smooth mirror and glass).
#include <gtest/gtest.h>

#include "materials/BsdfFactory.h"
#include "support/TestScenes.h"

using namespace envgi;

namespace {

double furnace(const Bsdf& b, int spp = 64) {
  auto scene = test::furnaceScene(b, 48, spp);
  EmbreeAccel accel(*scene);
  RenderOptions o;
  o.progress = false;
  RenderStats st;
  Image img = render(*scene, accel, o, &st);
  EXPECT_EQ(st.nonFiniteSamples, 0u);
  int n = 0;
  double m = test::meanOverObject(*scene, accel, img, &n);
  EXPECT_GT(n, 400);
  return m;
}

}  // namespace

TEST(Furnace, DiffuseGivesAlbedo) {
  Bsdf b;
  b.reflectance = Color(0.8f);
  EXPECT_NEAR(furnace(b), 0.8, 0.008);
}

TEST(Furnace, SmoothDielectricConservesEnergy) {
  Bsdf b;
  b.type = BsdfType::Dielectric;
  b.ior = 1.5f;
  EXPECT_NEAR(furnace(b), 1.0, 0.01);
}

TEST(Furnace, PerfectMirrorConservesEnergy) {
  Bsdf b;
  b.type = BsdfType::Conductor;
  b.perfectMirror = true;
  EXPECT_NEAR(furnace(b, 4), 1.0, 1e-4);
}

TEST(Furnace, RoughConductorNeverCreatesEnergy) {
  for (float a : {0.1f, 0.5f, 1.0f}) {
    Bsdf b;
    b.type = BsdfType::RoughConductor;
    b.perfectMirror = true;  // white: F = 1
    b.alpha = a;
    double m = furnace(b);
    EXPECT_LE(m, 1.0 + 0.01) << "alpha " << a;
    EXPECT_GT(m, 0.3) << "alpha " << a;  // GGX at alpha = 1 loses over half (see test_Bsdf)
  }
}

TEST(Furnace, RoughDielectricAndPlasticStayBelowOne) {
  Bsdf g;
  g.type = BsdfType::RoughDielectric;
  g.alpha = 0.3f;
  g.ior = 1.5f;
  double m = furnace(g);
  EXPECT_LE(m, 1.0 + 0.015);
  EXPECT_GT(m, 0.6);
  Bsdf p;
  p.type = BsdfType::Plastic;
  p.reflectance = Color(1.f);
  p.ior = 1.49f;
  finishPlastic(p);
  EXPECT_LE(furnace(p), 1.0 + 0.015);
}
