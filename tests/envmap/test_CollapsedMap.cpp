// The collapsed map (points strategy): its lights carry the map's power, the image it gives
// approaches the unbiased one as N grows, and it is deterministic for a seed.
#include <gtest/gtest.h>

#include "envmap/CollapsedMap.h"
#include "render/Renderer.h"
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
  scene->integrator.env.strategy = "points-draw";
  scene->finalize();
  EmbreeAccel accel(*scene);
  RenderOptions o;
  o.progress = false;
  o.spp = 4;
  Image img = render(*scene, accel, o, nullptr);
  Color centre = img.at(12, 12);  // the mirror ball: the sky reflected, not black
  EXPECT_GT(luminance(centre), 0.05f);
}

namespace {

// A diffuse floor (albedo 0.6) under skyWithSun, seen from above, `direct` with `strategy`.
struct FloorUnderSky {
  std::unique_ptr<Scene> scene;
  FloorUnderSky() {
    Bsdf floor;
    floor.reflectance = Color(0.6f);
    scene = test::sphereOnFloor(floor, floor, 3.f, skyWithSun(), Vec3f(0, 2.5f, 5.f), Vec3f(0, 0.6f, 0), 24, 40.f);
  }
  Image render(const std::string& strategy, int n, int spp, uint32_t seed = 1, const std::string& method = "sample") {
    scene->integrator = IntegratorSettings{};
    scene->integrator.type = IntegratorType::Direct;
    scene->integrator.setStrategy(strategy);
    scene->integrator.env.pointCount = n;
    scene->integrator.env.pointMethod = method;
    scene->sampler.seed = seed;
    scene->finalize();
    EmbreeAccel accel(*scene);
    RenderOptions o;
    o.progress = false;
    o.spp = spp;
    return envgi::render(*scene, accel, o, nullptr);
  }
};

double rmseOf(const Image& a, const Image& ref) {
  double e = 0.0;
  for (size_t i = 0; i < a.rgb.size(); ++i) e += sqr(double(a.rgb[i]) - ref.rgb[i]);
  return std::sqrt(e / double(a.rgb.size()));
}

}  // namespace

// `points` is the paper's collapsed map: every light at every shading point. A point on the
// floor that no light's shadow ray meets the ball gets exactly sum_i albedo/pi max(0, cos) E_i,
// computed here from the lights themselves, and no sample of it varies: the pixel is the
// same at 1 spp and at 16, with another sampler seed (median cut's set has no seed). Drawing
// one of the same lights a sample instead (points-draw) is noisy.
TEST(CollapsedMap, EveryLightLightsEveryPoint) {
  FloorUnderSky f;
  f.scene->spheres[0].center = Vec3f(0, -50, 0);  // the ball out of the way, below the floor
  Image one = f.render("points", 64, 1, 1, "mediancut");
  Image other = f.render("points", 64, 1, 99, "mediancut");
  const std::vector<DirectionalLight>& lights = f.scene->env->points();
  ASSERT_EQ(lights.size(), 64u);
  const Vec3f n(0, 1, 0);
  Color expected(0.f);
  for (const DirectionalLight& l : lights) expected += Color(0.6f) * (kInvPi * std::max(0.f, dot(n, l.dir))) * l.irradiance;
  Image many = f.render("points", 64, 16, 7, "mediancut");
  // Where the floor is open to the whole sky (the image's lower left corner), every sample of
  // every seed gives the same value, the sum itself.
  int exact = 0;
  for (const Image* img : {&one, &other, &many})
    for (int y = 20; y < 24; ++y)
      for (int x = 0; x < 3; ++x) {
        Color c = img->at(x, y);
        bool near = true;
        for (int k = 0; k < 3; ++k) near = near && std::fabs(c[k] - expected[k]) <= 1e-5f * expected[k];
        exact += near;
      }
  EXPECT_EQ(exact, 36) << "expected " << expected.x << " " << expected.y << " " << expected.z << ", got "
                       << one.at(0, 23).x << " " << one.at(0, 23).y << " " << one.at(0, 23).z;
  // One light drawn a sample (points-draw) is an unbiased estimate of that same sum: noisy.
  Image draw = f.render("points-draw", 64, 1, 1, "mediancut");
  EXPECT_GT(rmseOf(draw, one), 0.05 * luminance(expected));
}

// The paper's trade: at one sample a pixel the collapsed map's error against the converged
// image is far below Algorithm 1's (no noise from the map), and its bias, measured where the
// pixels' own area is converged (64 spp), falls as N grows.
TEST(CollapsedMap, AtOneSampleItBeatsImportanceAndItsBiasFallsWithN) {
  FloorUnderSky f;
  Image ref = f.render("mis", 0, 4096);
  const double importance = rmseOf(f.render("importance", 0, 1), ref);
  double last = 1e30;
  // Past a few hundred lights the bias is below the reference's own noise (about 0.006 here).
  for (int n : {4, 32, 256}) {
    const double atOne = rmseOf(f.render("points", n, 1), ref), bias = rmseOf(f.render("points", n, 64), ref);
    std::printf("points-%d: RMSE %.4f at 1 spp (importance %.4f, ratio %.3f), %.4f at 64 spp\n", n, atOne,
                importance, atOne / importance, bias);
    EXPECT_LT(bias, 0.7 * last) << "the bias falls as N grows";
    if (n >= 256) {
      EXPECT_LE(atOne, 0.3 * importance) << n;
    }
    last = bias;
  }
}

// Path tracing takes one light a bounce; the whole map at every vertex is refused there with
// the name of the strategy that does that (points-draw).
TEST(CollapsedMap, PathRefusesEveryLightAtEveryVertex) {
  FloorUnderSky f;
  f.scene->integrator = IntegratorSettings{};
  f.scene->integrator.type = IntegratorType::Path;
  f.scene->integrator.setStrategy("points");
  f.scene->finalize();
  EmbreeAccel accel(*f.scene);
  RenderOptions o;
  o.progress = false;
  o.spp = 1;
  try {
    envgi::render(*f.scene, accel, o, nullptr);
    ADD_FAILURE() << "path with points rendered";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("'points-draw'"), std::string::npos) << e.what();
  }
}
