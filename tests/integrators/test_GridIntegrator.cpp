// The grid integrator against the path tracer: a biased method, so region means within a
// stated bound rather than within noise; and from the command line's scene format.
#include <gtest/gtest.h>

#include "render/Renderer.h"
#include "scene/NameTables.h"
#include "support/TestScenes.h"

using namespace envgi;

namespace {
Image run(Scene& s, IntegratorType type, int spp) {
  s.integrator.type = type;
  s.sampler.sampleCount = spp;
  s.finalize();
  EmbreeAccel accel(s);
  RenderOptions o;
  o.progress = false;
  return render(s, accel, o, nullptr);
}
}  // namespace

// A white ball on a coloured floor under a sky with a bright band: direct light is exact
// (light sampling), the floor's light on the ball and the ball's on the floor come from the
// grid. Quadrant means within 5% of a 1024-spp path tracer.
TEST(GridIntegrator, MatchesPathOnASphereOnAFloor) {
  Bsdf floor;
  floor.reflectance = Color(0.7f, 0.5f, 0.3f);
  Bsdf ball;
  ball.reflectance = Color(0.8f);
  Image sky(128, 64);
  for (int y = 0; y < 64; ++y)
    for (int x = 0; x < 128; ++x) sky.set(x, y, Color(y < 4 ? 60.f : (y < 32 ? 0.5f : 0.05f)));
  auto scene = test::sphereOnFloor(floor, ball, 3.f, std::move(sky), Vec3f(0, 2.5f, 4.5f), Vec3f(0, 0.5f, 0), 16, 40.f);
  Image ref = run(*scene, IntegratorType::Path, 1024);
  scene->integrator.grid.resolution = 16;
  scene->integrator.grid.gatherRays = 64;
  scene->integrator.grid.globalPhotons = 50000;
  scene->integrator.grid.causticPhotons = 1000;
  Image grid = run(*scene, IntegratorType::Grid, 64);
  double total = 0.0;
  for (int ry = 0; ry < 16; ry += 8)
    for (int rx = 0; rx < 16; rx += 8) {
      double a = 0, b = 0;
      for (int y = ry; y < ry + 8; ++y)
        for (int x = rx; x < rx + 8; ++x) {
          a += luminance(ref.at(x, y)) / 64;
          b += luminance(grid.at(x, y)) / 64;
        }
      EXPECT_NEAR(b, a, 0.05 * a) << "quadrant " << rx << "," << ry;
      total += a;
    }
  EXPECT_GT(total, 0.0);
}

// Without any indirect light (a diffuse ball alone under a constant sky, seen from outside)
// the grid adds only what the ball reflects onto itself through nearby grid points: the
// smoothing bias, bounded here. The furnace value is the albedo.
TEST(GridIntegrator, FurnaceBiasIsBounded) {
  Bsdf b;
  b.reflectance = Color(0.6f);
  auto scene = test::furnaceScene(b, 16, 16);
  scene->integrator.grid.resolution = 8;
  scene->integrator.grid.gatherRays = 64;
  scene->integrator.grid.globalPhotons = 20000;
  scene->integrator.grid.causticPhotons = 0;
  Image img = run(*scene, IntegratorType::Grid, 16);
  EmbreeAccel accel(*scene);
  int count = 0;
  double mean = test::meanOverObject(*scene, accel, img, &count);
  ASSERT_GT(count, 20);
  EXPECT_GE(mean, 0.6 * 0.99);
  EXPECT_LE(mean, 0.6 * 1.15);
}
