// The collapsed map (points strategy): its lights carry the map's power, the image it gives
// approaches the unbiased one as N grows, and it is deterministic for a seed.
#include <gtest/gtest.h>

#include "envmap/CollapsedMap.h"
#include "support/TestScenes.h"

using namespace envgi;

namespace {

Image skyWithSun() {
  Image sky(128, 64);
  for (int y = 0; y < 64; ++y)
    for (int x = 0; x < 128; ++x) {
      bool sun = std::abs(x - 40) < 2 && std::abs(y - 14) < 2;
      sky.set(x, y, Color(0.2f + 0.3f * (y < 32), 0.3f, 0.5f - 0.004f * y) + Color(sun ? 200.f : 0.f));
    }
  return sky;
}

Color total(const std::vector<DirectionalLight>& pts) {
  Color s(0.f);
  for (const DirectionalLight& d : pts) s += d.irradiance;
  return s;
}

}  // namespace

TEST(CollapsedMap, LightsCarryTheMapsPower) {
  EnvironmentMapOptions o;
  o.scale = 2.f;
  EnvironmentMap map(skyWithSun(), o);
  Color power = map.stats().power;
  for (int n : {1, 7, 64, 256}) {
    std::vector<DirectionalLight> mc = collapseByMedianCut(map, n);
    EXPECT_EQ(int(mc.size()), n);
    Color t = total(mc);
    for (int k = 0; k < 3; ++k) EXPECT_NEAR(t[k], power[k], 2e-3 * power[k]) << "median cut, n " << n;
  }
  std::vector<DirectionalLight> ws = collapseByWeightedSampling(map, 4096, 3);
  Color t = total(ws);
  for (int k = 0; k < 3; ++k) EXPECT_NEAR(t[k], power[k], 0.03 * power[k]) << "weighted sampling";
  // Deterministic for a seed, different across seeds.
  std::vector<DirectionalLight> a = collapseByWeightedSampling(map, 16, 5), b = collapseByWeightedSampling(map, 16, 5),
                                c = collapseByWeightedSampling(map, 16, 6);
  for (int i = 0; i < 16; ++i) EXPECT_EQ(length(a[i].dir - b[i].dir), 0.f);
  double diff = 0.0;
  for (int i = 0; i < 16; ++i) diff += length(a[i].dir - c[i].dir);
  EXPECT_GT(diff, 0.0);
  EXPECT_THROW(collapseByMedianCut(map, 0), std::runtime_error);
  // Past the bound, refused before anything is allocated for the lights.
  EXPECT_THROW(collapseByMedianCut(map, kMaxCollapsedPoints + 1), std::runtime_error);
  EXPECT_THROW(collapseByWeightedSampling(map, 2000000000, 3), std::runtime_error);
}

// A diffuse ball on a diffuse floor: `direct` with the collapsed map against `direct` with
// Algorithm 1 at many samples. The error (bias) falls as N grows; with a mirror ball `path`
// still sees the map through it.
TEST(CollapsedMap, ImageApproachesTheUnbiasedOneAsNGrows) {
  Bsdf floor;
  floor.reflectance = Color(0.6f);
  auto scene = test::sphereOnFloor(floor, floor, 3.f, skyWithSun(), Vec3f(0, 2.5f, 5.f), Vec3f(0, 0.6f, 0), 24, 40.f);
  auto run = [&](const std::string& strategy, int n, const std::string& method, int spp) {
    scene->integrator = IntegratorSettings{};
    scene->integrator.type = IntegratorType::Direct;
    scene->integrator.env.strategy = strategy;
    scene->integrator.env.pointCount = n;
    scene->integrator.env.pointMethod = method;
    scene->finalize();
    EmbreeAccel accel(*scene);
    RenderOptions o;
    o.progress = false;
    o.spp = spp;
    return render(*scene, accel, o, nullptr);
  };
  Image ref = run("mis", 0, "sample", 2048);
  auto rmse = [&](const Image& a) {
    double e = 0.0;
    for (size_t i = 0; i < a.rgb.size(); ++i) e += sqr(a.rgb[i] - ref.rgb[i]);
    return std::sqrt(e / double(a.rgb.size()));
  };
  for (std::string method : {"mediancut", "sample"}) {
    double e4 = rmse(run("points", 4, method, 64)), e256 = rmse(run("points", 256, method, 64));
    std::printf("%s: rmse N=4 %.4f, N=256 %.4f\n", method.c_str(), e4, e256);
    EXPECT_LT(e256, 0.5 * e4) << method;
  }
  Bsdf mirror;
  mirror.type = BsdfType::Conductor;
  mirror.perfectMirror = true;
  scene->bsdfs[1] = mirror;
  scene->integrator = IntegratorSettings{};
  scene->integrator.type = IntegratorType::Path;
  scene->integrator.env.strategy = "points";
  scene->finalize();
  EmbreeAccel accel(*scene);
  RenderOptions o;
  o.progress = false;
  o.spp = 4;
  Image img = render(*scene, accel, o, nullptr);
  Color centre = img.at(12, 12);  // the mirror ball: the sky reflected, not black
  EXPECT_GT(luminance(centre), 0.05f);
}
