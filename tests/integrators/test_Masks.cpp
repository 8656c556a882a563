// Mitsuba's mask: a ray meets a masked surface and stops there with the chance of its opacity
// (SceneView::stopsAtMask), in both tracers and in every integrator. The tracers' statistics
// first, then renders whose expected value is known in closed form.
#include <gtest/gtest.h>

#include <cmath>

#include "accel/Bvh.h"
#include "accel/EmbreeAccel.h"
#include "render/Renderer.h"
#include "sampling/Pcg32.h"
#include "scene/Scene.h"
#include "support/TestScenes.h"

using namespace envgi;
using test::expectShare;

namespace {

constexpr float kOpacity = 0.3f;

Bsdf masked(float reflectance, float opacity) {
  Bsdf b;
  b.reflectance = Color(reflectance);
  b.opacity = opacity;
  return b;
}

// Adds a mesh shape with material `bsdf` to s.
void addMesh(Scene& s, TriangleMesh m, int bsdf) {
  s.meshes.push_back(std::move(m));
  s.shapes.push_back({false, s.meshes.size() - 1, bsdf, false, Color(0.f)});
}

// The rectangle [-1, 1]^2 at height z, facing +z.
TriangleMesh plane(float z) {
  TriangleMesh m = makeRectangle();
  m.transform(translate(Vec3f(0.f, 0.f, z)));
  return m;
}

struct Counts {
  int first = 0, second = 0, none = 0;  // rays stopped at the first surface, at the second, nowhere
};

// n rays down -z from z = 5 over x, y in (-0.3, 0.3) + offset, each classified by where it
// stopped (t below `split`: the first surface); for Embree and the BVH, which must agree ray by
// ray, and occluded() must agree with intersect().
Counts shoot(const Scene& s, Vec2f offset, float split, int n = 20000, float from = 5.f) {
  EmbreeAccel embree(s);
  Bvh bvh(s);
  BvhView bv = bvh.view();
  EXPECT_EQ(bv.masks != nullptr, s.view().hasMasks);
  Pcg32 rng(7, 1);
  Counts c;
  int disagree = 0;
  for (int i = 0; i < n; ++i) {
    Ray r{Vec3f(offset.x + 0.6f * (rng.nextFloat() - 0.5f), offset.y + 0.6f * (rng.nextFloat() - 0.5f), from),
          normalize(Vec3f(0.04f * (rng.nextFloat() - 0.5f), 0.04f * (rng.nextFloat() - 0.5f), from > 0.f ? -1.f : 1.f)), INFINITY};
    Hit he, hb, hs;
    bool e = embree.intersect(r, &he), b = bv.intersect(r, &hb);
    EXPECT_TRUE(embree.intersect(r, &hs, false)) << "intersectSurface sees every surface";
    disagree += e != b || (e && std::fabs(he.t - hb.t) > 1e-3f);
    EXPECT_EQ(embree.occluded(r.o, r.d, INFINITY), e);
    EXPECT_EQ(bv.occluded(r.o, r.d, INFINITY), b);
    if (!e) ++c.none;
    else if (he.t < split) ++c.first;
    else ++c.second;
  }
  EXPECT_LE(disagree, n / 1000) << "Embree and the BVH decide each crossing alike";
  return c;
}

// A binomial share within 4.5 standard deviations.

}  // namespace

TEST(Mask, StopsWithTheChanceOfItsOpacity) {
  Scene s;
  s.bsdfs = {masked(0.5f, kOpacity)};
  addMesh(s, plane(0.f), 0);
  s.finalize();
  ASSERT_TRUE(s.view().hasMasks);
  const int n = 20000;
  Counts c = shoot(s, Vec2f(0.f, 0.f), INFINITY, n);
  expectShare(c.first + c.second, n, kOpacity, "stopped");

  // Opacity 1 is opaque (and no mask at all), 0 lets everything through.
  for (float a : {0.f, 1.f}) {
    s.bsdfs[0].opacity = a;
    s.finalize();
    EXPECT_EQ(s.view().hasMasks, a < 1.f);
    Counts e = shoot(s, Vec2f(0.f, 0.f), INFINITY, 2000);
    EXPECT_EQ(e.first + e.second, a == 1.f ? 2000 : 0) << "opacity " << a;
  }
}

// Two masked planes one behind the other: each crossing is decided apart, so a ray stops at the
// first with the chance a, at the second with (1 - a) a.
TEST(Mask, CrossingsAlongARayAreIndependent) {
  Scene s;
  s.bsdfs = {masked(0.5f, kOpacity)};
  addMesh(s, plane(0.f), 0);
  addMesh(s, plane(-0.5f), 0);
  s.finalize();
  const int n = 20000;
  Counts c = shoot(s, Vec2f(0.f, 0.f), 5.25f, n);
  expectShare(c.first, n, kOpacity, "first plane");
  expectShare(c.second, n, (1.f - kOpacity) * kOpacity, "second plane");
  expectShare(c.none, n, (1.f - kOpacity) * (1.f - kOpacity), "through both");
}

// A ray through a masked sphere meets it twice, on the way in and on the way out.
TEST(Mask, ASphereIsCrossedTwice) {
  Scene s;
  s.bsdfs = {masked(0.5f, kOpacity)};
  s.spheres.push_back({Vec3f(0.f), 1.f, false});
  s.shapes.push_back({true, 0, 0, false, Color(0.f)});
  s.finalize();
  const int n = 20000;
  Counts c = shoot(s, Vec2f(0.f, 0.f), 5.f, n);
  expectShare(c.first, n, kOpacity, "way in");
  expectShare(c.second, n, (1.f - kOpacity) * kOpacity, "way out");
}

// An opacity texture: a checkerboard of 1 and 0 over the plane's (u, v) = ((x + 1) / 2, (y + 1) / 2)
// is opaque where u and v are in the same half, and lets every ray through elsewhere.
TEST(Mask, OpacityTextureIsReadAtTheHit) {
  Scene s;
  s.textures.push_back(test::checkerboard(1.f, 0.f));
  Bsdf b = masked(0.5f, 0.f);
  b.opacityTexture = 0;
  s.bsdfs = {b};
  addMesh(s, plane(0.f), 0);
  s.finalize();
  EXPECT_EQ(shoot(s, Vec2f(0.5f, 0.5f), INFINITY, 2000).none, 0);
  EXPECT_EQ(shoot(s, Vec2f(-0.5f, -0.5f), INFINITY, 2000).none, 0);
  EXPECT_EQ(shoot(s, Vec2f(0.5f, -0.5f), INFINITY, 2000).none, 2000);
  // From behind, the same.
  EXPECT_EQ(shoot(s, Vec2f(0.5f, 0.5f), INFINITY, 2000, -5.f).none, 0);
  EXPECT_EQ(shoot(s, Vec2f(-0.5f, 0.5f), INFINITY, 2000, -5.f).none, 2000);
}

namespace {

void lookThrough(Scene& s, Vec3f eye, Vec3f target, Vec3f up, float fovDeg) {
  s.env = std::make_unique<EnvironmentMap>(EnvironmentMap::constant(Color(1.f)));
  s.camera.toWorld = lookAt(eye, target, up);
  s.camera.width = s.camera.height = 24;
  s.camera.tanHalfX = s.camera.tanHalfY = std::tan(0.5f * fovDeg * kPi / 180.f);
  s.camera.filter = makeFilter(FilterType::Box);
}

const IntegratorType kAll[] = {IntegratorType::Path, IntegratorType::Direct, IntegratorType::Photon,
                               IntegratorType::Sppm, IntegratorType::Grid};

}  // namespace

// A masked diffuse plane filling the view under a sky of radiance 1: the camera sees the plane's
// rho with the chance a and the sky through it otherwise, a rho + 1 - a.
TEST(Mask, CameraSeesThroughByTheOpacity) {
  for (IntegratorType type : kAll) {
    Scene s;
    s.bsdfs = {masked(0.5f, kOpacity)};
    addMesh(s, plane(0.f), 0);
    lookThrough(s, Vec3f(0, 0, 4), Vec3f(0, 0, 0), Vec3f(0, 1, 0), 20.f);
    EXPECT_NEAR(test::renderedMean(s, type, 32), kOpacity * 0.5 + (1.0 - kOpacity), 0.012) << "integrator " << int(type);
  }
}

// A diffuse floor inside a black masked shell: every direction from the floor leaves through
// the shell once, so the floor receives 1 - a of the sky and shows rho (1 - a). The shadow rays
// and the BSDF's rays pass the shell alike; photons that pass it reach the floor unbounced,
// which is direct light, not the photon maps' (were the pass counted as a bounce, the floor
// would show about twice as much).
TEST(Mask, ShellShadowsByTheOpacity) {
  for (IntegratorType type : kAll) {
    Scene s;
    s.bsdfs = {masked(0.f, kOpacity), Bsdf{}};
    s.spheres.push_back({Vec3f(0.f), 3.f, false});
    s.shapes.push_back({true, 0, 0, false, Color(0.f)});
    TriangleMesh floor = makeRectangle();
    floor.transform(rotate(Vec3f(1, 0, 0), -90.f));  // facing +y
    addMesh(s, floor, 1);
    lookThrough(s, Vec3f(0, 2, 0), Vec3f(0, 0, 0), Vec3f(0, 0, 1), 40.f);
    EXPECT_NEAR(test::renderedMean(s, type, 32), 0.5 * (1.0 - kOpacity), 0.012) << "integrator " << int(type);
  }
}
