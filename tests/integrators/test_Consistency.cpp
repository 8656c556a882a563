// The direct integrator with every environment strategy and the path integrator at
// max_depth = 2 estimate the same image: a per-region Z-test on their means, with variances
// from the renderer, Sidak-corrected over all regions and pairs (as Mitsuba's render tests).
#include <gtest/gtest.h>

#include "support/ChiSquare.h"
#include "support/TestScenes.h"
#include "scene/NameTables.h"

using namespace envgi;

namespace {

// A glossy sphere on a diffuse floor under a smooth synthetic sky with a broad bright patch.
std::unique_ptr<Scene> makeScene() {
  Bsdf floor;
  floor.reflectance = Color(0.6f, 0.55f, 0.5f);
  Bsdf glossy;
  glossy.type = BsdfType::RoughConductor;
  glossy.perfectMirror = true;
  glossy.specularReflectance = Color(0.8f);
  glossy.alpha = 0.35f;
  Image sky(64, 32);
  for (int y = 0; y < 32; ++y)
    for (int x = 0; x < 64; ++x) {
      float patch = (std::abs(x - 20) < 5 && std::abs(y - 8) < 4) ? 6.f : 0.f;
      sky.set(x, y, Color(0.3f + 0.02f * (32 - y) + patch, 0.35f + patch, 0.4f + 0.5f * patch));
    }
  auto s = test::sphereOnFloor(floor, glossy, 4.f, std::move(sky), Vec3f(0, 2.5f, 5.f), Vec3f(0, 0.8f, 0), 16, 40.f);
  s->sampler.type = SamplerType::Independent;
  s->sampler.sampleCount = 256;
  s->finalize();
  return s;
}

struct Result {
  Image img;
  std::vector<float> var;
};

Result run(Scene& s, const std::string& integrator, const std::string& strategy, uint32_t seed) {
  s.integrator = IntegratorSettings{};
  s.integrator.type = findIntegrator(integrator);
  s.integrator.env.strategy = strategy;
  if (integrator == "path") s.integrator.path.maxDepth = 2;
  s.sampler.seed = seed;
  s.finalize();
  EmbreeAccel accel(s);
  RenderOptions o;
  o.progress = false;
  Result r;
  o.varianceOut = &r.var;
  RenderStats st;
  r.img = render(s, accel, o, &st);
  EXPECT_EQ(st.nonFiniteSamples, 0u);
  return r;
}

double rmse(const Image& a, const Image& ref) {
  double e = 0.0;
  for (size_t i = 0; i < a.rgb.size(); ++i) e += (a.rgb[i] - ref.rgb[i]) * (a.rgb[i] - ref.rgb[i]);
  return std::sqrt(e / double(a.rgb.size()));
}

}  // namespace

TEST(Consistency, DirectStrategiesAgreeWithPathDepth2) {
  auto scene = makeScene();
  Result ref = run(*scene, "path", "mis", 1);
  const std::vector<std::string> strategies = {"uniform",  "cosine", "bsdf",   "importance",
                                               "alias",    "adaptive", "mis", "product"};
  const int region = 4, regions = (16 / region) * (16 / region);
  const double alpha = test::sidakAlpha(int(strategies.size()) * regions);
  for (size_t k = 0; k < strategies.size(); ++k) {
    Result r = run(*scene, "direct", strategies[k], uint32_t(100 + k));
    double minP = 1.0;
    for (int ry = 0; ry < 16; ry += region)
      for (int rx = 0; rx < 16; rx += region) {
        double m1 = 0, m2 = 0, v1 = 0, v2 = 0;
        for (int y = ry; y < ry + region; ++y)
          for (int x = rx; x < rx + region; ++x) {
            m1 += luminance(ref.img.at(x, y));
            m2 += luminance(r.img.at(x, y));
            v1 += ref.var[size_t(y) * 16 + x];
            v2 += r.var[size_t(y) * 16 + x];
          }
        double n = region * region;
        double z = (m1 / n - m2 / n) / std::sqrt((v1 + v2) / (n * n) + 1e-12);
        double p = std::erfc(std::fabs(z) / std::sqrt(2.0));
        minP = std::min(minP, p);
      }
    EXPECT_GT(minP, alpha) << "strategy " << strategies[k];
  }
}

// The importance strategy beats uniform sampling in RMS error at equal sample count, on a map
// whose light is concentrated (the paper's Figure 9 claim, on a small case).
TEST(Consistency, ImportanceBeatsUniformAtEqualSamples) {
  auto scene = makeScene();
  scene->sampler.sampleCount = 4096;
  Result ref = run(*scene, "direct", "mis", 7);
  scene->sampler.sampleCount = 16;
  Result uni = run(*scene, "direct", "uniform", 8);
  scene->sampler.sampleCount = 16;
  Result imp = run(*scene, "direct", "importance", 9);
  EXPECT_LT(rmse(imp.img, ref.img), 0.8 * rmse(uni.img, ref.img));
}

// The product strategy (map times a cosine bound) beats Algorithm 1's density with BSDF samples
// (mis) at equal samples on the diffuse floor and glossy sphere: fewer light samples wasted
// below the surface. Measured: RMSE 0.0482 against 0.0719.
TEST(Consistency, ProductBeatsMisAtEqualSamples) {
  auto scene = makeScene();
  scene->sampler.sampleCount = 4096;
  Result ref = run(*scene, "direct", "mis", 7);
  scene->sampler.sampleCount = 16;
  Result mis = run(*scene, "direct", "mis", 8);
  scene->sampler.sampleCount = 16;
  Result product = run(*scene, "direct", "product", 8);
  EXPECT_LT(rmse(product.img, ref.img), 0.85 * rmse(mis.img, ref.img));
}
