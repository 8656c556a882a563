// Renders through Mitsuba's orthographic camera in every integrator: a black sphere under a
// sky of radiance 1 hides the share of the view its disk covers, the same from near and far.
#include <gtest/gtest.h>

#include <cmath>

#include "scene/Scene.h"
#include "support/TestScenes.h"

using namespace envgi;

namespace {

// A black sphere of radius 0.5 at the origin, seen from `distance` along +z by a square
// camera: orthographic with the near plane's [-1, 1]^2, or perspective with a 60-degree view.
Scene blackSphere(float distance, bool orthographic) {
  Scene s;
  Bsdf black;
  black.reflectance = Color(0.f);
  s.bsdfs = {black};
  s.spheres.push_back({Vec3f(0.f), 0.5f, false});
  s.shapes.push_back({true, 0, 0, false, Color(0.f)});
  s.env = std::make_unique<EnvironmentMap>(EnvironmentMap::constant(Color(1.f)));
  s.camera.toWorld = lookAt(Vec3f(0, 0, distance), Vec3f(0, 0, 0), Vec3f(0, 1, 0));
  s.camera.width = s.camera.height = 32;
  s.camera.orthographic = orthographic;
  s.camera.tanHalfX = s.camera.tanHalfY = orthographic ? 1.f : std::tan(30.f * kPi / 180.f);
  s.camera.filter = makeFilter(FilterType::Box);
  return s;
}

}  // namespace

// The disk covers pi r^2 of the view's 2 x 2, so the image's mean is 1 - pi / 16 at any
// distance; through a perspective camera the sphere shrinks with distance (the check's teeth).
TEST(Orthographic, ASphereHidesItsDiskFromNearAndFar) {
  const double expected = 1.0 - kPi * 0.25 / 4.0;
  for (IntegratorType type :
       {IntegratorType::Path, IntegratorType::Direct, IntegratorType::Photon, IntegratorType::Sppm, IntegratorType::Grid})
    for (float distance : {1.2f, 20.f}) {
      Scene s = blackSphere(distance, true);
      EXPECT_NEAR(test::renderedMean(s, type, 16), expected, 0.004)
          << "integrator " << int(type) << ", distance " << distance;
    }
  Scene nearView = blackSphere(1.2f, false), farView = blackSphere(20.f, false);
  double nearMean = test::renderedMean(nearView, IntegratorType::Path, 16);
  double farMean = test::renderedMean(farView, IntegratorType::Path, 16);
  EXPECT_LT(nearMean, 0.6);  // 1 - 0.49: the disk fills half the view
  EXPECT_GT(farMean, 0.99);
}

// Mitsuba's cylinder seen from its side: a black tube of radius 0.5 and length 1 across the
// view hides its 1 x 1 outline, a quarter of the 2 x 2 view, at any distance.
TEST(Orthographic, ACylinderHidesItsOutline) {
  for (float distance : {1.2f, 20.f}) {
    Scene s = blackSphere(distance, true);
    s.spheres.clear();
    s.meshes.push_back(makeCylinder(Vec3f(0.f, -0.5f, 0.f), Vec3f(0.f, 0.5f, 0.f), 0.5f));
    s.shapes = {{false, 0, 0, false, Color(0.f)}};
    EXPECT_NEAR(test::renderedMean(s, IntegratorType::Path, 16), 0.75, 0.004) << "distance " << distance;
  }
}
