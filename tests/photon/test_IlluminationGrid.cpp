// The illumination grid's pieces: L1 irradiance from SH, trilinear reads that skip points
// inside geometry, and the grid's extent over a scene.
#include <gtest/gtest.h>

#include "photon/IlluminationGrid.h"
#include "sampling/Sampler.h"
#include "sampling/Warp.h"

using namespace envgi;

namespace {
// SH of a radiance function, projected with n Sobol directions over the sphere.
template <class F>
ShL1 project(F radiance, int n) {
  ShL1 s;
  Sampler smp;
  smp.type = SamplerType::Sobol;
  smp.spp = uint32_t(n);
  for (int i = 0; i < n; ++i) {
    smp.start(7, uint32_t(i));
    Vec3f d = sampleUniformSphere(smp.get2D());
    float y[4];
    shL1Basis(d, y);
    for (int c = 0; c < 4; ++c) s.c[c] += Color(radiance(d) * y[c] / uniformSpherePdf() / float(n));
  }
  return s;
}
}  // namespace

// Constant radiance L gives pi L for every normal; a uniform upper hemisphere gives pi L
// facing it, 0 facing away and pi L / 2 sideways: exact for L1, so only the projection's
// error (4096 Sobol directions) remains.
TEST(IlluminationGrid, L1IrradianceIsExactForConstantAndHemisphereLight) {
  ShL1 c = project([](Vec3f) { return 2.f; }, 4096);
  for (Vec3f n : {Vec3f(0, 0, 1), Vec3f(1, 0, 0), normalize(Vec3f(1, -2, 3))})
    EXPECT_NEAR(shL1Irradiance(c, n).x, 2.f * kPi, 1e-3);
  ShL1 h = project([](Vec3f d) { return d.z > 0.f ? 1.f : 0.f; }, 4096);
  EXPECT_NEAR(shL1Irradiance(h, Vec3f(0, 0, 1)).x, kPi, 5e-3);
  EXPECT_NEAR(shL1Irradiance(h, Vec3f(0, 0, -1)).x, 0.f, 5e-3);
  EXPECT_NEAR(shL1Irradiance(h, Vec3f(0, 1, 0)).x, 0.5f * kPi, 5e-3);
}

TEST(IlluminationGrid, ReadsAConstantFieldAndSkipsPointsInsideGeometry) {
  IlluminationGrid g(Vec3f(0.f), Vec3f(1.f), 3, 3, 3);
  EXPECT_EQ(g.pointCount(), 27u);
  EXPECT_FLOAT_EQ(g.point(26).x, 1.f);
  EXPECT_FLOAT_EQ(g.point(1).x, 0.5f);
  ShL1 one = project([](Vec3f) { return 1.f; }, 1024);
  for (size_t i = 0; i < g.pointCount(); ++i) g.accumulate(i, one, 1, 0);
  // Point 13 (the centre) is inside something: most of its rays met back faces, and its value
  // is absurd; a read next to it must not see it.
  ShL1 huge = one;
  for (Color& c : huge.c) c = c * 1e6f;
  g.accumulate(13, huge, 3, 3);
  g.finish();
  EXPECT_EQ(g.view().weight[13], 0.f);
  EXPECT_EQ(g.view().weight[12], 1.f);
  for (Vec3f p : {Vec3f(0.1f), Vec3f(0.45f, 0.5f, 0.55f), Vec3f(0.9f, 0.2f, 0.7f), Vec3f(-3.f), Vec3f(5.f)})
    EXPECT_NEAR(g.view().irradiance(p, Vec3f(0, 1, 0)).x, kPi, 2e-3) << p.x << " " << p.y << " " << p.z;
  EXPECT_THROW(IlluminationGrid(Vec3f(0.f), Vec3f(1.f), 1, 3, 3), std::runtime_error);
}

// Points behind the surface (on the far side of a wall) count less than points in front.
TEST(IlluminationGrid, PointsBehindTheSurfaceCountLess) {
  IlluminationGrid g(Vec3f(0.f), Vec3f(1.f), 2, 2, 2);
  ShL1 dark = project([](Vec3f) { return 0.f; }, 64), lit = project([](Vec3f) { return 1.f; }, 1024);
  for (size_t i = 0; i < g.pointCount(); ++i) g.accumulate(i, g.point(i).y > 0.5f ? lit : dark, 1, 0);
  g.finish();
  // Halfway up, facing +y: the lit points are in front, so the read leans to them.
  float up = g.view().irradiance(Vec3f(0.5f), Vec3f(0, 1, 0)).x;
  float down = g.view().irradiance(Vec3f(0.5f), Vec3f(0, -1, 0)).x;
  EXPECT_GT(up, 0.8f * kPi);
  EXPECT_LT(down, 0.2f * kPi);
  EXPECT_GT(up, 5.f * down);
}
