// Mitsuba's blendbsdf: where a ray meets the surface, the material is the blend's second with
// the chance of its weight, else its first (SceneView::blendChoice). The choice's statistics
// first, then renders whose expected value is known in closed form, in every integrator.
#include <gtest/gtest.h>

#include <cmath>

#include "accel/EmbreeAccel.h"
#include "sampling/Pcg32.h"
#include "scene/Scene.h"
#include "support/TestBsdfs.h"
#include "support/TestScenes.h"

using namespace envgi;
using test::diffuse;
using test::expectShare;
using test::mirror;

namespace {

Bsdf blendOf(int first, int second, float weight) {
  Bsdf b;
  b.blend0 = first;
  b.blend1 = second;
  b.blendWeight = weight;
  return b;
}

// The rectangle [-1, 1]^2 at z = 0, facing +z, with material `bsdf`.
void addPlane(Scene& s, int bsdf) {
  s.meshes.push_back(makeRectangle());
  s.shapes.push_back({false, s.meshes.size() - 1, bsdf, false, Color(0.f)});
}

// How often each material is what n rays down -z over x, y in (-0.3, 0.3) + offset find at
// their first hit; with `through`, also at the second (a sphere's way out: the ray goes on from
// the first hit).
std::vector<int> choices(const Scene& s, Vec2f offset, int n, bool through = false) {
  EmbreeAccel accel(s);
  const SceneView& v = s.view();
  Pcg32 rng(11, 3);
  std::vector<int> count(s.bsdfs.size() * (through ? s.bsdfs.size() : 1), 0);
  for (int i = 0; i < n; ++i) {
    Ray r{Vec3f(offset.x + 0.6f * (rng.nextFloat() - 0.5f), offset.y + 0.6f * (rng.nextFloat() - 0.5f), 5.f),
          normalize(Vec3f(0.02f * (rng.nextFloat() - 0.5f), 0.02f * (rng.nextFloat() - 0.5f), -1.f)), INFINITY};
    Hit h;
    if (!accel.intersect(r, &h)) continue;
    int first = v.interaction(r, h).bsdf;
    if (!through) {
      ++count[size_t(first)];
      continue;
    }
    Ray on{r.o + r.d * (h.t + 1e-3f), r.d, INFINITY};
    Hit h2;
    if (!accel.intersect(on, &h2)) continue;
    ++count[size_t(first) * s.bsdfs.size() + size_t(v.interaction(on, h2).bsdf)];
  }
  return count;
}

// interaction() at the first hit of a ray down -z through (x, y), the scene finalized.
SurfaceInteraction firstHit(Scene& s, float x, float y) {
  s.finalize();
  EmbreeAccel accel(s);
  Ray r{Vec3f(x, y, 5.f), Vec3f(0.f, 0.f, -1.f), INFINITY};
  Hit h;
  EXPECT_TRUE(accel.intersect(r, &h));
  return s.view().interaction(r, h);
}

}  // namespace

// A blend of materials 0 and 1 at weight 0.3 hands out 1 at 30% of the hits and never itself;
// weights 0 and 1 hand out one material only; a blend nested in a blend multiplies the chances.
TEST(Blend, ChoosesTheSecondWithTheChanceOfItsWeight) {
  const int n = 20000;
  Scene s;
  s.bsdfs = {diffuse(0.2f), diffuse(0.8f), blendOf(0, 1, 0.3f)};
  addPlane(s, 2);
  s.finalize();
  std::vector<int> c = choices(s, Vec2f(0.f, 0.f), n);
  EXPECT_EQ(c[0] + c[1], n);
  expectShare(c[1], n, 0.3, "second");
  for (float w : {0.f, 1.f}) {
    s.bsdfs[2].blendWeight = w;
    s.finalize();
    c = choices(s, Vec2f(0.f, 0.f), 2000);
    EXPECT_EQ(c[w == 1.f ? 1 : 0], 2000) << "weight " << w;
  }
  // blend(blend(0, 1, 0.5), mirror, 0.4): 0.3, 0.3, 0.4.
  Scene t;
  t.bsdfs = {diffuse(0.2f), diffuse(0.8f), blendOf(0, 1, 0.5f), mirror(), blendOf(2, 3, 0.4f)};
  addPlane(t, 4);
  t.finalize();
  c = choices(t, Vec2f(0.f, 0.f), n);
  expectShare(c[0], n, 0.3, "nested first");
  expectShare(c[1], n, 0.3, "nested second");
  expectShare(c[3], n, 0.4, "outer second");
}

// A weight texture, a checkerboard of 1 and 0 over the plane's (u, v): the second material
// where u and v are in the same half, the first elsewhere.
TEST(Blend, WeightTextureIsReadAtTheHit) {
  Scene s;
  s.textures.push_back(test::checkerboard(1.f, 0.f));
  Bsdf b = blendOf(0, 1, 0.f);
  b.blendWeightTexture = 0;
  s.bsdfs = {diffuse(0.2f), diffuse(0.8f), b};
  addPlane(s, 2);
  s.finalize();
  EXPECT_EQ(choices(s, Vec2f(0.5f, 0.5f), 2000)[1], 2000);
  EXPECT_EQ(choices(s, Vec2f(-0.5f, -0.5f), 2000)[1], 2000);
  EXPECT_EQ(choices(s, Vec2f(0.5f, -0.5f), 2000)[0], 2000);
}

// A ray through a blended sphere chooses on the way in and on the way out apart: the four pairs
// come with the products of their chances. Under a mask (opacity 0.5), the rays that stop choose
// as often as those that would not: the two draws are apart.
TEST(Blend, ASpheresTwoCrossingsAndTheMaskChooseApart) {
  const int n = 20000;
  Scene s;
  s.bsdfs = {diffuse(0.2f), diffuse(0.8f), blendOf(0, 1, 0.3f)};
  s.spheres.push_back({Vec3f(0.f), 1.f, false});
  s.shapes.push_back({true, 0, 2, false, Color(0.f)});
  s.finalize();
  std::vector<int> c = choices(s, Vec2f(0.f, 0.f), n, true);
  const size_t k = s.bsdfs.size();
  expectShare(c[0 * k + 0], n, 0.7 * 0.7, "first, first");
  expectShare(c[0 * k + 1], n, 0.7 * 0.3, "first, second");
  expectShare(c[1 * k + 0], n, 0.3 * 0.7, "second, first");
  expectShare(c[1 * k + 1], n, 0.3 * 0.3, "second, second");

  s.bsdfs[2].opacity = 0.5f;
  s.finalize();
  c = choices(s, Vec2f(0.f, 0.f), n);
  const int stopped = c[0] + c[1];
  expectShare(stopped, n, 0.5 + 0.5 * 0.5, "stopped on the way in or out");
  expectShare(c[1], stopped, 0.3, "second among the stopped");
}

// The path tracer's partner: for a one-level blend of two plain materials, the one not chosen
// and its weight in the mix; none for nested blends, for a transmitting material, or where a
// weight of 0 or 1 leaves one material alone.
TEST(Blend, InteractionNamesTheOtherMaterialOfAOneLevelBlend) {
  auto partnerAt = [](Scene& s, int* chosen, float* weight) {
    SurfaceInteraction si = firstHit(s, 0.1f, 0.2f);
    *chosen = si.bsdf;
    *weight = si.partnerWeight;
    return si.partner;
  };
  int chosen;
  float weight;
  for (bool sphere : {false, true}) {
    Scene s;
    s.bsdfs = {diffuse(0.2f), diffuse(0.8f), blendOf(0, 1, 0.3f)};
    if (sphere) {
      s.spheres.push_back({Vec3f(0.f), 1.f, false});
      s.shapes.push_back({true, 0, 2, false, Color(0.f)});
    } else {
      addPlane(s, 2);
    }
    int partner = partnerAt(s, &chosen, &weight);
    EXPECT_EQ(partner, 1 - chosen) << "sphere " << sphere;
    EXPECT_FLOAT_EQ(weight, chosen == 0 ? 0.3f : 0.7f) << "sphere " << sphere;
    s.bsdfs[2].blendWeight = 1.f;
    EXPECT_EQ(partnerAt(s, &chosen, &weight), -1);
    EXPECT_EQ(chosen, 1);
  }
  Scene nested;
  nested.bsdfs = {diffuse(0.2f), diffuse(0.8f), blendOf(0, 1, 0.5f), mirror(), blendOf(2, 3, 0.4f)};
  addPlane(nested, 4);
  EXPECT_EQ(partnerAt(nested, &chosen, &weight), -1);
  Scene glass;
  Bsdf g;
  g.type = BsdfType::Dielectric;
  glass.bsdfs = {diffuse(0.2f), g, blendOf(0, 1, 0.5f)};
  addPlane(glass, 2);
  EXPECT_EQ(partnerAt(glass, &chosen, &weight), -1);
}

// A blend on a sphere whose normals are flipped: the hit's (u, v), where the chosen material's
// textures and the partner's weight are read, is the point's own, as on the unflipped sphere.
TEST(Blend, AFlippedSpheresBlendReadsThePointsOwnUv) {
  auto uvAt = [](bool flip) {
    Scene s;
    s.bsdfs = {diffuse(0.2f), diffuse(0.8f), blendOf(0, 1, 0.3f)};
    s.spheres.push_back({Vec3f(0.f), 1.f, flip});
    s.shapes.push_back({true, 0, 2, false, Color(0.f)});
    return firstHit(s, 0.3f, 0.4f).uv;
  };
  const Vec2f plain = uvAt(false), flipped = uvAt(true);
  EXPECT_FLOAT_EQ(flipped.x, plain.x);
  EXPECT_FLOAT_EQ(flipped.y, plain.y);
}

namespace {

// A sphere of radius 1 filling an orthographic view ([-0.5, 0.5]^2, inside its outline) under a
// sky of radiance 1, its material the blend: the image's mean is the blend's furnace value.
Scene blendFurnace(std::vector<Bsdf> bsdfs) {
  Scene s;
  s.bsdfs = std::move(bsdfs);
  s.spheres.push_back({Vec3f(0.f), 1.f, false});
  s.shapes.push_back({true, 0, int(s.bsdfs.size() - 1), false, Color(0.f)});
  s.env = std::make_unique<EnvironmentMap>(EnvironmentMap::constant(Color(1.f)));
  s.camera.toWorld = lookAt(Vec3f(0, 0, 4), Vec3f(0, 0, 0), Vec3f(0, 1, 0));
  s.camera.width = s.camera.height = 16;
  s.camera.orthographic = true;
  s.camera.tanHalfX = s.camera.tanHalfY = 0.5f;
  s.camera.filter = makeFilter(FilterType::Box);
  s.integrator.path.maxDepth = 16;
  return s;
}

double furnace(std::vector<Bsdf> bsdfs, IntegratorType type) {
  Scene s = blendFurnace(std::move(bsdfs));
  return test::renderedMean(s, type, 32);
}

}  // namespace

// The path and direct integrators evaluate the whole mix: the pixels of the two-diffuse furnace
// at 4 samples spread about 0.35 by what the map's and the BSDF's samples leave (RMS 0.032),
// where the choice alone (0.2 or 0.8 a sample) spreads them by 0.135.
TEST(Blend, PathAndDirectEvaluateTheWholeMix) {
  for (IntegratorType type : {IntegratorType::Path, IntegratorType::Direct}) {
    Scene s = blendFurnace({diffuse(0.2f), diffuse(0.8f), blendOf(0, 1, 0.25f)});
    s.integrator.type = type;
    s.sampler.sampleCount = 4;
    Image img = test::renderedImage(s);
    double sum2 = 0.0;
    for (int y = 0; y < img.height; ++y)
      for (int x = 0; x < img.width; ++x) sum2 += sqr(double(img.at(x, y).y) - 0.35);
    const double rms = std::sqrt(sum2 / (img.width * img.height));
    EXPECT_LT(rms, 0.06) << "integrator " << int(type);
  }
  // The same mix one level down (a blend of it with itself), which is left to the choice alone.
  Scene s = blendFurnace({diffuse(0.2f), diffuse(0.8f), blendOf(0, 1, 0.25f), blendOf(2, 2, 0.5f)});
  s.integrator.type = IntegratorType::Path;
  s.sampler.sampleCount = 4;
  Image img = test::renderedImage(s);
  double sum2 = 0.0;
  for (int y = 0; y < img.height; ++y)
    for (int x = 0; x < img.width; ++x) sum2 += sqr(double(img.at(x, y).y) - 0.35);
  EXPECT_GT(std::sqrt(sum2 / (img.width * img.height)), 0.1);
}

// A textured material as the partner (its own copy at the hit, beside the chosen one's): the
// whole mix and the same mix one level down (the choice alone) show the same mean, the
// texture's.
TEST(Blend, ATexturedPartnerIsReadAtTheHit) {
  auto mean = [](bool nested) {
    Bsdf checker = diffuse(0.2f);  // the texture's 0.1 and 0.9 in its place: 0.5 on average
    checker.reflectanceTexture = 0;
    std::vector<Bsdf> bsdfs = {checker, diffuse(0.5f), blendOf(0, 1, 0.6f)};
    if (nested) bsdfs.push_back(blendOf(2, 2, 0.5f));
    Scene s = blendFurnace(bsdfs);
    s.textures.push_back(test::checkerboard(0.1f, 0.9f));
    return test::renderedMean(s, IntegratorType::Path, 64);
  };
  const double whole = mean(false), chosen = mean(true);
  EXPECT_NEAR(whole, chosen, 0.01);
  EXPECT_NEAR(whole, 0.5, 0.01);  // about 0.43 if the partner took its untextured 0.2
}

// Under a sky of radiance 1 a convex diffuse sphere shows its albedo and a mirror shows the sky:
// a blend shows (1 - w) of the first and w of the second. Two diffuse materials (0.75 x 0.2 +
// 0.25 x 0.8 = 0.35), and a diffuse one with a mirror (0.6 x 0.5 + 0.4 = 0.7), which the photon
// integrators follow along their specular chains.
TEST(Blend, FurnaceShowsTheWeightedMix) {
  for (IntegratorType type :
       {IntegratorType::Path, IntegratorType::Direct, IntegratorType::Photon, IntegratorType::Sppm, IntegratorType::Grid}) {
    EXPECT_NEAR(furnace({diffuse(0.2f), diffuse(0.8f), blendOf(0, 1, 0.25f)}, type), 0.35, 0.01) << "integrator " << int(type);
    EXPECT_NEAR(furnace({diffuse(0.5f), mirror(), blendOf(0, 1, 0.4f)}, type), 0.7, 0.01) << "integrator " << int(type);
  }
}
