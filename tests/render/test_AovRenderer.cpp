// The AOVs of a camera's first hits, against what the geometry says: a plane seen head-on by an
// orthographic camera has exactly its distance from the near plane as depth, its
// normal, its material's albedo; pixels that miss read 0 (-1 for the indices).
#include <gtest/gtest.h>

#include <cmath>

#include "render/AovRenderer.h"
#include "support/TestScenes.h"

using namespace envgi;

namespace {

// A 32^2 camera at z = 5 looking down -z at the square [-0.5, 0.5]^2 (shape 1, material
// `plane`) at z = 0 and a sphere of radius 0.1 centred over pixel (28, 3), 1 above the plane
// (shape 0, material `ball`):
// the film spans [-1, 1]^2 for the orthographic camera, so its outer ring of pixels misses.
Scene planeScene(const Bsdf& plane, const Bsdf& ball, bool orthographic, float nearClip = 1e-2f) {
  Scene s;
  s.bsdfs = {plane, ball};
  s.spheres.push_back({Vec3f(0.78125f, 0.78125f, 1.f), 0.1f, false});  // on pixel (28, 3)
  s.shapes.push_back({true, 0, 1, false, Color(0.f)});
  TriangleMesh m = makeRectangle();
  m.transform(scale(Vec3f(0.5f)));
  s.meshes.push_back(m);
  s.shapes.push_back({false, 0, 0, false, Color(0.f)});
  s.env = std::make_unique<EnvironmentMap>(EnvironmentMap::constant(Color(1.f)));
  s.camera.toWorld = lookAt(Vec3f(0, 0, 5), Vec3f(0, 0, 0), Vec3f(0, 1, 0));
  s.camera.width = s.camera.height = 32;
  s.camera.orthographic = orthographic;
  s.camera.nearClip = nearClip;
  s.camera.tanHalfX = s.camera.tanHalfY = orthographic ? 1.f : std::tan(10.f * kPi / 180.f);
  s.camera.filter = makeFilter(FilterType::Box);
  s.sampler.type = SamplerType::Sobol;
  s.aovs = parseAovs("alb:albedo,dd:depth,p:position,nn:sh_normal,ng:geo_normal,i:prim_index,s:shape_index,t:uv");
  s.finalize();
  return s;
}

const ImageChannel& channel(const std::vector<ImageChannel>& cs, const std::string& name) {
  for (const ImageChannel& c : cs)
    if (c.name == name) return c;
  throw std::runtime_error("no channel " + name);
}

Bsdf diffuse(float rho) {
  Bsdf b;
  b.reflectance = Color(rho);
  return b;
}

}  // namespace

TEST(AovRenderer, APlaneHeadOnGivesItsDepthNormalAndAlbedo) {
  Bsdf mirror;
  mirror.type = BsdfType::Conductor;
  mirror.perfectMirror = true;
  mirror.specularReflectance = Color(0.8f, 0.6f, 0.4f);
  Scene s = planeScene(diffuse(0.3f), mirror, true);
  EmbreeAccel accel(s);
  std::vector<ImageChannel> cs = renderAovs(s, accel, 64, 1);
  ASSERT_EQ(cs.size(), 17u);
  auto at = [&](const std::string& name, int x, int y) { return channel(cs, name).values[size_t(y) * 32 + size_t(x)]; };
  for (int y = 9; y < 23; ++y)
    for (int x = 9; x < 23; ++x) {
      // Every ray of these pixels meets the plane: 5 units from the camera, less the near plane.
      EXPECT_NEAR(at("dd.T", x, y), 5.f - 1e-2f, 1e-5f);
      EXPECT_NEAR(at("alb.R", x, y), 0.3f, 1e-5f) << "a diffuse surface's albedo is its reflectance";
      EXPECT_NEAR(at("nn.Z", x, y), 1.f, 1e-6f);
      EXPECT_NEAR(at("ng.Z", x, y), 1.f, 1e-6f);
      EXPECT_NEAR(at("p.Z", x, y), 0.f, 1e-6f);
      // The box filter's samples average to the pixel's centre (image right is world +x here).
      EXPECT_NEAR(at("p.X", x, y), -1.f + (x + 0.5f) / 16.f, 0.01f) << x;
      EXPECT_NEAR(at("p.Y", x, y), 1.f - (y + 0.5f) / 16.f, 0.01f) << y;
      EXPECT_NEAR(at("t.U", x, y), (at("p.X", x, y) + 0.5f), 0.01f) << "the rectangle's (u, v) = (x + 1) / 2";
      EXPECT_EQ(at("s.I", x, y), 1.f) << "the plane is the second shape";
      EXPECT_GE(at("i.I", x, y), 0.f);
      EXPECT_LE(at("i.I", x, y), 1.f) << "one of its two triangles";
    }
  // The sphere's centre pixel: a mirror's albedo is its specular reflectance (Fresnel 1).
  const int sx = 28, sy = 3;
  EXPECT_EQ(at("s.I", sx, sy), 0.f);
  EXPECT_NEAR(at("alb.R", sx, sy), 0.8f, 1e-5f);
  EXPECT_NEAR(at("alb.B", sx, sy), 0.4f, 1e-5f);
  // Its (u, v) though its material reads none (interaction() leaves them out): seen from above,
  // the pixel holds polar angles up to asin(0.044 / 0.1), v = theta / pi about 0.06 on average.
  EXPECT_GT(at("t.V", sx, sy), 0.03f);
  EXPECT_LT(at("t.V", sx, sy), 0.1f);
  // Its cap over the pixel's square [-a, a]^2 (a = 1/32) lies sqrt(r^2 - x^2 - y^2) above its
  // centre, r - 2 a^2 / (3 * 2 r) on average to second order.
  const float a = 1.f / 32.f, cap = 0.1f - 2.f * a * a / 3.f / 0.2f;
  EXPECT_NEAR(at("dd.T", sx, sy), 5.f - 1e-2f - 1.f - cap, 1e-3f);
  // The corner pixel misses everything.
  for (const char* name : {"dd.T", "alb.R", "p.X", "nn.Z", "t.U"}) EXPECT_EQ(at(name, 0, 31), 0.f) << name;
  EXPECT_EQ(at("s.I", 0, 31), -1.f);
  EXPECT_EQ(at("i.I", 0, 31), -1.f);
}

// Depth is Mitsuba's si.t, the distance from where the camera ray starts, on the near plane:
// the centre pixel of a perspective camera sees the plane 5 away, less near_clip (Mitsuba 3.9.1's
// aov integrator agrees: scripts/crosscheck_aovs.py).
TEST(AovRenderer, DepthCountsFromTheNearPlaneAsMitsubas) {
  for (float nearClip : {1e-2f, 1.f, 3.f}) {
    Scene s = planeScene(diffuse(0.5f), diffuse(0.5f), false, nearClip);
    EmbreeAccel accel(s);
    std::vector<ImageChannel> cs = renderAovs(s, accel, 16, 2);
    const float centre = channel(cs, "dd.T").values[16 * 32 + 16];
    EXPECT_NEAR(centre, 5.f - nearClip, 2e-3f) << nearClip;
  }
}

// The same AOVs on 1 and 2 threads, and from a second call: the samples are addressed by pixel.
TEST(AovRenderer, TheSameWhateverTheThreads) {
  Scene s = planeScene(diffuse(0.5f), diffuse(0.2f), false);
  EmbreeAccel accel(s);
  std::vector<ImageChannel> a = renderAovs(s, accel, 8, 1), b = renderAovs(s, accel, 8, 2);
  ASSERT_EQ(a.size(), b.size());
  for (size_t i = 0; i < a.size(); ++i) EXPECT_EQ(a[i].values, b[i].values) << a[i].name;
}

// The film's alpha, as Mitsuba's: 1 everywhere while the environment is seen; with it hidden,
// the share of a pixel's rays that meet a surface (1 inside the plane, 0 beyond it, between on
// its edge).
TEST(AovRenderer, AlphaIsCoverageWhereTheEnvironmentIsHidden) {
  Scene s = planeScene(diffuse(0.5f), diffuse(0.5f), true);
  // Half a pixel to the right: the plane's right edge, x = 0.53125, halves pixel column 24.
  s.meshes[0].transform(translate(Vec3f(1.f / 32.f, 0.f, 0.f)));
  s.aovs = {Aov{"", AovType::Alpha}};
  s.finalize();
  EmbreeAccel accel(s);
  std::vector<ImageChannel> seen = renderAovs(s, accel, 16, 1);
  ASSERT_EQ(seen.size(), 1u);
  EXPECT_EQ(seen[0].name, "A");
  for (float v : seen[0].values) ASSERT_EQ(v, 1.f);
  s.integrator.path.hideEmitters = true;
  std::vector<ImageChannel> hidden = renderAovs(s, accel, 16, 1);
  auto at = [&](int x, int y) { return hidden[0].values[size_t(y) * 32 + size_t(x)]; };
  EXPECT_EQ(at(16, 16), 1.f);
  EXPECT_EQ(at(0, 31), 0.f);
  EXPECT_EQ(at(23, 16), 1.f);
  EXPECT_NEAR(at(24, 16), 0.5f, 0.2f) << "half the pixel's rays meet the plane";
  EXPECT_EQ(at(25, 16), 0.f);
}
