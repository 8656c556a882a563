// The photon integrators against the path tracer: SPPM converges to it on a diffuse scene, the
// photon integrator's error falls as photons grow, and caustics appear under glass.
#include <gtest/gtest.h>

#include "materials/BsdfFactory.h"
#include "support/CausticScene.h"
#include "scene/NameTables.h"

using namespace envgi;

namespace {

std::unique_ptr<Scene> diffuseScene(bool glassSphere) {
  Bsdf floor;
  floor.reflectance = Color(0.7f, 0.6f, 0.5f);
  Bsdf ball;
  ball.reflectance = Color(0.3f, 0.6f, 0.8f);
  if (glassSphere) {
    ball.type = BsdfType::Dielectric;
    ball.ior = 1.5f;
  }
  // A sky with a bright band high above: sharp shadows, a sharp caustic.
  Image sky(128, 64);
  for (int y = 0; y < 64; ++y)
    for (int x = 0; x < 128; ++x) sky.set(x, y, Color(y < 2 ? 400.f : (y < 32 ? 0.4f : 0.05f)));
  return test::sphereOnFloor(floor, ball, 3.f, std::move(sky), Vec3f(0, 3.5f, 4.5f), Vec3f(0, 0.5f, 0), 16, 45.f);
}

Image run(Scene& s, const std::string& type, int spp, std::vector<float>* var = nullptr) {
  s.integrator.type = findIntegrator(type);
  s.sampler.sampleCount = spp;
  s.finalize();
  EmbreeAccel accel(s);
  RenderOptions o;
  o.progress = false;
  o.varianceOut = var;
  RenderStats st;
  return render(s, accel, o, &st);
}

}  // namespace

// Region means of SPPM lie within 4 sigma of the path tracer's (its variance from the
// renderer) plus 4% for SPPM's remaining bias.
TEST(PhotonConsistency, SppmMatchesPathOnDiffuseScene) {
  auto scene = diffuseScene(false);
  std::vector<float> var;
  Image ref = run(*scene, "path", 1024, &var);
  scene->integrator.sppm.passes = 128;
  scene->integrator.sppm.photonCount = 20000;
  Image sppm = run(*scene, "sppm", -1);
  for (int ry = 0; ry < 16; ry += 4)
    for (int rx = 0; rx < 16; rx += 4) {
      double a = 0, b = 0, v = 0;
      for (int y = ry; y < ry + 4; ++y)
        for (int x = rx; x < rx + 4; ++x) {
          a += luminance(ref.at(x, y)) / 16;
          b += luminance(sppm.at(x, y)) / 16;
          v += var[size_t(y) * 16 + x] / 256;
        }
      EXPECT_NEAR(b, a, 4 * std::sqrt(v) + 0.04 * a) << "region " << rx << "," << ry;
    }
}

TEST(PhotonConsistency, PhotonErrorFallsWithPhotonCount) {
  auto scene = diffuseScene(false);
  Image ref = run(*scene, "path", 1024);
  auto rmse = [&](size_t photons) {
    scene->integrator.photon.globalPhotons = photons;
    scene->integrator.photon.causticPhotons = photons / 4;
    scene->integrator.photon.gatherSamples = 0;  // read the global map directly: the photon error shows
    Image img = run(*scene, "photon", 16);
    double e = 0;
    for (size_t i = 0; i < img.rgb.size(); ++i) e += sqr(img.rgb[i] - ref.rgb[i]);
    return std::sqrt(e / img.rgb.size());
  };
  double small = rmse(2000), large = rmse(100000);
  EXPECT_LT(large, small) << "rmse " << small << " -> " << large;
}

// A glass ball under a small sun focuses it into a caustic brighter than the sunlit floor
// around it, with both photon integrators.
TEST(PhotonConsistency, CausticAppearsUnderGlass) {
  test::CausticSetup cs = test::causticScene(48);
  EmbreeAccel accel(*cs.scene);
  std::vector<int> focus = test::floorPixels(*cs.scene, accel, cs.causticCentre, 0.f, 0.15f);
  std::vector<int> ring = test::floorPixels(*cs.scene, accel, cs.causticCentre, 1.8f, 2.6f);
  ASSERT_GT(focus.size(), 3u);
  ASSERT_GT(ring.size(), 20u);
  for (const char* type : {"sppm", "photon"}) {
    Scene& s = *cs.scene;
    s.integrator.sppm.passes = 24;
    s.integrator.sppm.photonCount = 100000;
    s.integrator.photon.globalPhotons = 20000;
    s.integrator.photon.causticPhotons = 100000;
    s.integrator.photon.gatherSamples = 2;
    Image img = run(s, type, 4);
    double a = test::meanLum(img, focus), b = test::meanLum(img, ring);
    EXPECT_GT(a, 1.5 * b) << type << ": caustic " << a << " vs surround " << b;
  }
}

// A smooth-plastic floor (dark base, so its coat's mirror image dominates) beside a lit white
// ball: both photon integrators follow the coat, so the ball's reflection appears and SPPM
// matches the path tracer over every region, the reflection included.
TEST(PhotonConsistency, SmoothPlasticReflectsLitSurfaces) {
  Bsdf floor;
  floor.type = BsdfType::Plastic;
  floor.reflectance = Color(0.05f);
  floor.ior = 1.5f;
  finishPlastic(floor);
  Bsdf ball;
  ball.reflectance = Color(0.8f);
  Image sky(128, 64);
  for (int y = 0; y < 64; ++y)
    for (int x = 0; x < 128; ++x) sky.set(x, y, Color(y < 3 ? 300.f : (y < 32 ? 0.3f : 0.02f)));
  auto scene = test::sphereOnFloor(floor, ball, 4.f, std::move(sky), Vec3f(0, 1.2f, 5.f), Vec3f(0, 0.6f, 0), 16, 40.f);
  std::vector<float> var;
  Image ref = run(*scene, "path", 1024, &var);
  scene->integrator.sppm.passes = 256;
  scene->integrator.sppm.photonCount = 40000;
  Image sppm = run(*scene, "sppm", -1);
  scene->integrator.photon.globalPhotons = 100000;
  scene->integrator.photon.causticPhotons = 20000;
  scene->integrator.photon.gatherSamples = 8;
  Image photon = run(*scene, "photon", 64);
  for (int ry = 0; ry < 16; ry += 4)
    for (int rx = 0; rx < 16; rx += 4) {
      double a = 0, b = 0, c = 0, v = 0;
      for (int y = ry; y < ry + 4; ++y)
        for (int x = rx; x < rx + 4; ++x) {
          a += luminance(ref.at(x, y)) / 16;
          b += luminance(sppm.at(x, y)) / 16;
          c += luminance(photon.at(x, y)) / 16;
          v += var[size_t(y) * 16 + x] / 256;
        }
      EXPECT_NEAR(b, a, 4 * std::sqrt(v) + 0.04 * a) << "sppm, region " << rx << "," << ry;
      // The photon integrator's final gather approximates the base as Lambertian: looser.
      EXPECT_NEAR(c, a, 4 * std::sqrt(v) + 0.10 * a) << "photon, region " << rx << "," << ry;
    }
}

namespace {
// A white floor under a mirror ceiling (one-sided, facing down) a little above it, under a
// constant sky: the floor below the mirror sees mostly the mirror, which shows the floor, so
// much of its light went sky -> floor -> mirror -> floor, a path in neither photon map.
std::unique_ptr<Scene> floorUnderAMirror() {
  Bsdf floor, mirror;
  floor.reflectance = Color(0.8f);
  mirror.type = BsdfType::Conductor;
  mirror.perfectMirror = true;
  mirror.specularReflectance = Color(0.9f);
  Image sky(16, 8);
  for (float& v : sky.rgb) v = 1.f;
  auto s = test::sphereOnFloor(floor, mirror, 3.f, std::move(sky), Vec3f(0, 0.5f, 2.5f), Vec3f(0, 0, 0), 16, 40.f);
  s->spheres.clear();
  s->shapes.pop_back();
  TriangleMesh ceiling = makeRectangle();
  ceiling.transform(scale(Vec3f(2.f)));
  ceiling.transform(rotate(Vec3f(1, 0, 0), 90.f));  // facing -y
  ceiling.transform(translate(Vec3f(0.f, 0.8f, 0.f)));
  s->meshes.push_back(ceiling);
  s->shapes.push_back({false, 1, 1, false, Color(0.f)});
  s->finalize();
  return s;
}
}  // namespace

// Gather rays follow a mirror to the diffuse surface behind it: under the mirror the photon
// integrator (final gather on) matches the path tracer within 3% on every quadrant, and the grid
// too (its SH basis within 10%). When the final gather dropped rays that met the mirror the floor read
// 59% dark there.
TEST(PhotonConsistency, GatherRaysFollowMirrorsToDiffuseSurfaces) {
  auto scene = floorUnderAMirror();
  Image ref = run(*scene, "path", 1024);
  const std::vector<double> a = test::quadrantMeans(ref);
  auto expectQuadrantsNear = [&](const Image& img, const char* what, double tolerance) {
    const std::vector<double> b = test::quadrantMeans(img);
    for (int q = 0; q < 4; ++q) {
      std::printf("%s quadrant %d: path %.4f, %.4f (%+.1f%%)\n", what, q, a[q], b[q], 100.0 * (b[q] / a[q] - 1.0));
      EXPECT_NEAR(b[q], a[q], tolerance * a[q]) << what << " quadrant " << q;
    }
  };
  scene->integrator.photon.globalPhotons = 100000;
  scene->integrator.photon.causticPhotons = 100000;
  scene->integrator.photon.gatherSamples = 16;
  expectQuadrantsNear(run(*scene, "photon", 64), "photon", 0.03);
  GridSettings& g = scene->integrator.grid;
  g.resolution = 16;
  g.gatherRays = g.maxGatherRays = 256;
  g.globalPhotons = 100000;
  g.causticPhotons = 100000;
  for (const char* basis : {"sh", "directions"}) {
    g.basis = basis;
    // The SH grid reads 6-8% low under the mirror (L1 smoothing), the paper's within 1%.
    expectQuadrantsNear(run(*scene, "grid", 64), basis, g.basis == "sh" ? 0.1 : 0.03);
  }
}

namespace {
// A white floor meeting a white wall (both one-sided, facing into the corner) under a constant
// sky, seen from in front of the corner.
std::unique_ptr<Scene> corner() {
  Bsdf white;
  white.reflectance = Color(0.8f);
  Image sky(16, 8);
  for (float& v : sky.rgb) v = 1.f;
  auto s = test::sphereOnFloor(white, white, 3.f, std::move(sky), Vec3f(0, 1.2f, 3.f), Vec3f(0, 0.3f, 0), 64, 40.f);
  s->spheres.clear();
  s->shapes.clear();
  s->meshes[0].transform(translate(Vec3f(0.f, 0.f, 3.f)));  // the floor ends at the wall
  s->shapes.push_back({false, 0, 0, false, Color(0.f)});
  TriangleMesh wall = makeRectangle();  // facing +z, at z = 0
  wall.transform(scale(Vec3f(3.f)));
  wall.transform(translate(Vec3f(0.f, 3.f, 0.f)));
  s->meshes.push_back(wall);
  s->shapes.push_back({false, 1, 0, false, Color(0.f)});
  // A ball above the corner: light it reflects reaches the wall from above, on the floor's side.
  s->spheres.push_back({Vec3f(0.f, 1.f, 0.9f), 0.5f, false});
  s->shapes.push_back({true, 0, 0, false, Color(0.f)});
  s->finalize();
  return s;
}
}  // namespace

// Eq. 12 in a corner, read from the global map directly (no final gather). The suspicion was
// that photons on the wall, lit from the floor's side (here by the ball), are counted on the
// floor and over-estimate there, since the estimate checks the side a photon came from and not
// the surface it lies on. Measured: within 0.05 of the edge the corner reads low, -10.0%: the
// search disc (k = 120 photons, radius about 0.07) reaches past the edge. Those wall photons
// (8,374 of the 7 M looked at) offset a little of that: dropping them by orientation
// (|n_photon . n| <= 0.9) took the band to -12.4%. So the estimate keeps them. Farther out
// every band is within 2% of path.
TEST(PhotonConsistency, ACornerReadsLowNotHigh) {
  auto scene = corner();
  Image ref = run(*scene, "path", 256);
  scene->integrator.photon.globalPhotons = 400000;
  scene->integrator.photon.causticPhotons = 0;
  scene->integrator.photon.gatherSamples = 0;
  Image ph = run(*scene, "photon", 16);
  EmbreeAccel accel(*scene);
  const Camera& c = scene->view().camera;
  double bands[4][2] = {};
  int counts[4] = {};
  for (int y = 0; y < c.height; ++y)
    for (int x = 0; x < c.width; ++x) {
      Hit h;
      Ray r = c.generateRay(x + 0.5f, y + 0.5f);
      if (!accel.intersect(r, &h)) continue;
      Vec3f p = r.o + r.d * h.t;
      float d = std::max(p.y, p.z);  // distance to the corner line (the other is 0)
      int band = d < 0.05f ? 0 : d < 0.1f ? 1 : d < 0.2f ? 2 : 3;
      bands[band][0] += luminance(ref.at(x, y));
      bands[band][1] += luminance(ph.at(x, y));
      counts[band]++;
    }
  for (int b = 0; b < 4; ++b) {
    ASSERT_GT(counts[b], 50) << "band " << b;
    const double path = bands[b][0] / counts[b], photon = bands[b][1] / counts[b];
    std::printf("band %d (%d px): path %.4f photon %.4f (%+.1f%%)\n", b, counts[b], path, photon,
                100.0 * (photon / path - 1.0));
    if (b == 0) {
      EXPECT_LT(photon, path) << "the corner reads high";
      EXPECT_GT(photon, 0.8 * path);
    } else {
      EXPECT_NEAR(photon, path, 0.02 * path) << "band " << b;
    }
  }
}
