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

// A thin lens: rays for one film position leave points spread over the aperture disk (on the
// lens plane, z = near along each ray) and all cross at that position's point of the plane in
// focus, which projects back to the film position; a radius of 0 gives the pinhole's rays.
TEST(Camera, ThinLensRaysMeetOnThePlaneInFocus) {
  Camera c;
  c.width = c.height = 128;
  c.tanHalfX = c.tanHalfY = 0.4f;
  c.nearClip = 0.01f;
  c.farClip = 1000.f;
  c.toWorld = lookAt(Vec3f(0.f, 1.f, 5.f), Vec3f(0.f, 0.5f, 0.f), Vec3f(0.f, 1.f, 0.f));
  Camera pinhole = c;
  c.apertureRadius = 0.2f;
  c.focusDistance = 4.f;
  ASSERT_TRUE(c.hasLens());
  ASSERT_FALSE(pinhole.hasLens());
  Pcg32 rng(4);
  double meanR2 = 0.0;
  const int n = 4000;
  for (int i = 0; i < n; ++i) {
    float x = rng.nextFloat() * 128.f, y = rng.nextFloat() * 128.f;
    Vec2f lens(rng.nextFloat(), rng.nextFloat());
    Ray r = c.generateRay(x, y, lens), p = pinhole.generateRay(x, y, lens);
    ASSERT_NEAR(length(r.d), 1.f, 1e-6f);
    Vec3f o = c.toWorld.inversePoint(r.o), d = c.toWorld.inverseVector(r.d);
    // Back along the ray to the lens plane z = 0: a point within the aperture.
    Vec3f onLens = o - d * (o.z / d.z);
    ASSERT_LE(std::hypot(onLens.x, onLens.y), c.apertureRadius * 1.0001f);
    meanR2 += double(onLens.x * onLens.x + onLens.y * onLens.y);
    ASSERT_NEAR(o.z, c.nearClip, 1e-5f);
    ASSERT_NEAR(c.toWorld.inversePoint(r.o + r.d * r.tMax).z, c.farClip, 5e-2f);
    // On the plane in focus it meets the pinhole ray of the same film position.
    Vec3f focus = onLens + d * ((c.focusDistance - onLens.z) / d.z);
    Vec3f pd = c.toWorld.inverseVector(p.d);
    Vec3f pinFocus = pd * (c.focusDistance / pd.z);
    ASSERT_NEAR(length(focus - pinFocus), 0.f, 1e-4f);
    float px, py;
    ASSERT_TRUE(projectToFilm(c, c.toWorld.point(focus), &px, &py));
    ASSERT_NEAR(px, x, 2e-3f);
    ASSERT_NEAR(py, y, 2e-3f);
  }
  // Uniform over the disk: E[r^2] = R^2 / 2.
  EXPECT_NEAR(meanR2 / n, 0.5 * 0.04, 0.02 * 0.04);
}

// Mitsuba's orthographic camera: every ray runs along the frame's +z, from the film position's
// point of the near plane, [-1, 1] x [-1/aspect, 1/aspect] in camera space before to_world
// (here scaled by 3 across and 2 up), image left at camera +x as for the perspective camera;
// the ray is far - near long, and the point projects back to its film position.
TEST(Camera, OrthographicRaysAreParallelFromTheNearPlane) {
  Camera c;
  c.width = 200;
  c.height = 100;
  c.orthographic = true;
  c.tanHalfX = 1.f;
  c.tanHalfY = 0.5f;
  c.nearClip = 0.1f;
  c.farClip = 50.f;
  Transform frame = lookAt(Vec3f(1.f, 2.f, 6.f), Vec3f(0.f, 0.5f, 0.f), Vec3f(0.f, 1.f, 0.f));
  c.toWorld = frame * scale(Vec3f(3.f, 2.f, 1.f));
  const Vec3f axis = normalize(frame.vector(Vec3f(0.f, 0.f, 1.f)));
  Pcg32 rng(5);
  for (int i = 0; i < 2000; ++i) {
    float x = rng.nextFloat() * 200.f, y = rng.nextFloat() * 100.f;
    Ray r = c.generateRay(x, y);
    ASSERT_NEAR(length(r.d - axis), 0.f, 1e-6f);
    ASSERT_NEAR(r.tMax, 49.9f, 1e-5f);
    Vec3f q = frame.inversePoint(r.o);
    ASSERT_NEAR(q.x, 3.f * (1.f - 2.f * x / 200.f), 1e-4f);
    ASSERT_NEAR(q.y, 2.f * 0.5f * (1.f - 2.f * y / 100.f), 1e-4f);
    ASSERT_NEAR(q.z, 0.1f, 1e-5f);
    float px, py;
    ASSERT_TRUE(projectToFilm(c, r.o + r.d * 7.f, &px, &py));
    ASSERT_NEAR(px, x, 2e-3f);
    ASSERT_NEAR(py, y, 2e-3f);
  }
  // The film's corners are the near plane's, a ray's length from the image plane does not
  // matter, and a point before the near plane is not seen.
  EXPECT_NEAR(length(frame.inversePoint(c.generateRay(0.f, 0.f).o) - Vec3f(3.f, 1.f, 0.1f)), 0.f, 1e-5f);
  EXPECT_NEAR(length(frame.inversePoint(c.generateRay(200.f, 100.f).o) - Vec3f(-3.f, -1.f, 0.1f)), 0.f, 1e-5f);
  float px, py;
  EXPECT_FALSE(projectToFilm(c, frame.point(Vec3f(0.f, 0.f, 0.05f)), &px, &py));
  EXPECT_FALSE(c.hasLens());
}

// Mitsuba's crop window: the cropped camera's pixel (x, y) is the whole film's (x + cropX,
// y + cropY), to the bit, for the pinhole, the thin lens and the orthographic camera alike, and
// a point projects back to the window's own coordinates (outside it: not on the image).
TEST(Camera, ACropWindowSeesItsPartOfTheFilm) {
  for (int kind = 0; kind < 3; ++kind) {
    Camera full;
    full.width = 64;
    full.height = 48;
    full.tanHalfX = 0.5f;
    full.tanHalfY = 0.375f;
    full.toWorld = lookAt(Vec3f(1.f, 2.f, 6.f), Vec3f(0.f, 0.5f, 0.f), Vec3f(0.f, 1.f, 0.f));
    if (kind == 1) {
      full.apertureRadius = 0.1f;
      full.focusDistance = 5.f;
    }
    full.orthographic = kind == 2;
    Camera crop = full;
    crop.filmWidth = 64;
    crop.filmHeight = 48;
    crop.cropX = 30;
    crop.cropY = 12;
    crop.width = 20;
    crop.height = 10;
    Pcg32 rng(3);
    for (int i = 0; i < 500; ++i) {
      float x = rng.nextFloat() * 20.f, y = rng.nextFloat() * 10.f;
      Vec2f lens(rng.nextFloat(), rng.nextFloat());
      Ray a = crop.generateRay(x, y, lens), b = full.generateRay(x + 30.f, y + 12.f, lens);
      ASSERT_EQ(a.o.x, b.o.x);
      ASSERT_EQ(a.o.z, b.o.z);
      ASSERT_EQ(a.d.y, b.d.y);
      ASSERT_EQ(a.tMax, b.tMax);
      float px, py;
      ASSERT_TRUE(projectToFilm(crop, b.o + b.d * 3.f, &px, &py) || kind == 1);
      if (kind != 1) {  // a thin lens's ray crosses the film position's line only in focus
        ASSERT_NEAR(px, x, 2e-3f);
        ASSERT_NEAR(py, y, 2e-3f);
      }
    }
    float px, py;
    EXPECT_FALSE(projectToFilm(crop, full.generateRay(10.f, 30.f).o + full.generateRay(10.f, 30.f).d * 3.f, &px, &py))
        << "a point left of the window";
  }
}
