// direct's two MIS heuristics (the paper's Eq. 5-6 balance heuristic, and the power heuristic):
// both weightings sum to one, so both estimate the same image (a per-region Z-test against a
// long render with the other), yet they weight differently (the images differ).
#include <gtest/gtest.h>

#include "render/Renderer.h"
#include "scene/Properties.h"
#include "support/ChiSquare.h"
#include "support/RegionZTest.h"
#include "support/TestScenes.h"

using namespace envgi;

namespace {

struct Rendered {
  Image image;
  std::vector<float> variance;
};

Rendered renderDirect(Scene& s, const std::string& heuristic, int spp, uint32_t seed) {
  s.integrator = IntegratorSettings{};
  s.integrator.type = IntegratorType::Direct;
  s.integrator.setStrategy("mis");
  s.integrator.direct.misHeuristic = heuristic;
  s.sampler.seed = seed;
  s.finalize();
  EmbreeAccel accel(s);
  RenderOptions o;
  o.progress = false;
  o.spp = spp;
  Rendered r;
  o.varianceOut = &r.variance;
  r.image = render(s, accel, o, nullptr);
  return r;
}

std::unique_ptr<Scene> glossyBallOnFloor() {
  Bsdf floor;
  floor.reflectance = Color(0.6f);
  Bsdf ball;
  ball.type = BsdfType::RoughConductor;
  ball.alpha = 0.15f;
  Image sky(64, 32);
  for (int y = 0; y < 32; ++y)
    for (int x = 0; x < 64; ++x) sky.set(x, y, Color((std::abs(x - 20) < 2 && y < 6) ? 300.f : 0.3f));
  return test::sphereOnFloor(floor, ball, 3.f, std::move(sky), Vec3f(0, 2.f, 4.5f), Vec3f(0, 0.7f, 0), 32, 40.f);
}

}  // namespace

TEST(DirectHeuristics, BalanceAndPowerEstimateTheSameImage) {
  auto scene = glossyBallOnFloor();
  Rendered balance = renderDirect(*scene, "balance", 64, 1);
  Rendered power = renderDirect(*scene, "power", 256, 2);
  int regions = 0;
  const double p = test::minRegionP(balance.image, balance.variance, power.image, power.variance, 4, &regions);
  EXPECT_GT(p, test::sidakAlpha(regions)) << "regions " << regions;
  // Same seed, same draws, other weights: a different image.
  Rendered powerSameSeed = renderDirect(*scene, "power", 64, 1);
  double diff = 0.0;
  for (size_t i = 0; i < balance.image.rgb.size(); ++i) diff += std::fabs(balance.image.rgb[i] - powerSameSeed.image.rgb[i]);
  EXPECT_GT(diff, 0.0) << "the heuristic is used";
}

TEST(DirectHeuristics, AnUnknownHeuristicIsAnError) {
  Properties p;
  p.set("mis_heuristic", "string", "cubic");
  EXPECT_THROW(DirectSettings::fromProperties(p), std::runtime_error);
}
