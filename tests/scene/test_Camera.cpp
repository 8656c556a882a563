// The perspective camera's rays: unit directions through the film position they were made for,
// starting on the near plane and ending on the far plane.
#include <gtest/gtest.h>

#include "sampling/Pcg32.h"
#include "scene/Camera.h"

using namespace envgi;

TEST(Camera, RaysStartOnTheNearPlaneAndProjectBackToTheirPixel) {
  Camera c;
  c.width = 320;
  c.height = 200;
  c.tanHalfY = std::tan(0.5f * 40.f * kPi / 180.f);
  c.tanHalfX = c.tanHalfY * 320.f / 200.f;
  c.nearClip = 0.05f;
  c.farClip = 500.f;
  c.toWorld = lookAt(Vec3f(1.f, 2.f, 6.f), Vec3f(0.f, 0.5f, 0.f), Vec3f(0.f, 1.f, 0.f));
  Vec3f eye = c.toWorld.point(Vec3f(0.f));
  Pcg32 rng(9);
  for (int i = 0; i < 5000; ++i) {
    float x = rng.nextFloat() * 320.f, y = rng.nextFloat() * 200.f;
    Ray r = c.generateRay(x, y);
    ASSERT_NEAR(length(r.d), 1.f, 1e-6f);
    // Camera space: the origin on z = near, the end of the ray on z = far.
    ASSERT_NEAR(c.toWorld.inversePoint(r.o).z, c.nearClip, 1e-5f);
    ASSERT_NEAR(c.toWorld.inversePoint(r.o + r.d * r.tMax).z, c.farClip, 5e-3f);
    // The ray leaves the eye and lands on the film position it was made for.
    ASSERT_NEAR(dot(normalize(r.o - eye), r.d), 1.f, 1e-5f);
    float px, py;
    ASSERT_TRUE(projectToFilm(c, r.o + r.d * 3.f, &px, &py));
    ASSERT_NEAR(px, x, 2e-3f);
    ASSERT_NEAR(py, y, 2e-3f);
  }
}
