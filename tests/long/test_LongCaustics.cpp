// Long checks (ctest -L long): SPPM against a long path-traced reference on a caustic scene,
// at equal render time with the path tracer, in the caustic region. Prints the figures.
#include <gtest/gtest.h>

#include <chrono>

#include "support/CausticScene.h"
#include "scene/NameTables.h"

using namespace envgi;

namespace {

struct Timed {
  Image img;
  double seconds;
};

Timed run(Scene& s, const std::string& type, int spp) {
  s.integrator.type = findIntegrator(type);
  s.integrator.path.maxDepth = 16;
  s.sampler.sampleCount = spp;
  s.sampler.type = SamplerType::Independent;
  s.finalize();
  EmbreeAccel accel(s);
  RenderOptions o;
  o.progress = false;
  RenderStats st;
  auto t0 = std::chrono::steady_clock::now();
  Image img = render(s, accel, o, &st);
  return {std::move(img), std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count()};
}

double rmse(const Image& a, const Image& ref, const std::vector<int>& px) {
  double e = 0.0;
  for (int i : px)
    for (int k = 0; k < 3; ++k) e += sqr(a.rgb[size_t(i) * 3 + k] - ref.rgb[size_t(i) * 3 + k]);
  return std::sqrt(e / (3.0 * px.size()));
}

void equalTime(bool chrome) {
  test::CausticSetup cs = test::causticScene(48, chrome);
  Scene& s = *cs.scene;
  if (chrome) {
    // The mirror ball throws the sun back onto the floor on the sun's side (x ~ 1 to 2.2).
    s.camera.toWorld = lookAt(Vec3f(4.5f, 3.5f, 0.5f), Vec3f(1.3f, 0.f, 0.f), Vec3f(0, 1, 0));
    s.finalize();
  }
  EmbreeAccel accel(s);
  Timed ref = run(s, "path", 1 << 15);
  // Glass focuses the sun behind the ball; a mirror ball throws it back onto the floor on the
  // sun's side.
  std::vector<int> region;
  if (!chrome) {
    region = test::floorPixels(s, accel, cs.causticCentre, 0.f, 0.5f);
  } else {
    region = test::floorPixels(s, accel, Vec3f(1.6f, 0.f, 0.f), 0.f, 0.6f);
  }
  ASSERT_GT(region.size(), 10u);
  // Many cheap passes: each pass is also one camera sample (direct light, anti-aliasing).
  s.integrator.sppm.passes = 512;
  s.integrator.sppm.photonCount = 25000;
  s.integrator.sppm.maxDepth = 16;
  Timed sppm = run(s, "sppm", -1);
  Timed probe = run(s, "path", 16);
  int spp = std::max(1, int(16.0 * sppm.seconds / probe.seconds));
  Timed path = run(s, "path", spp);
  double eS = rmse(sppm.img, ref.img, region), eP = rmse(path.img, ref.img, region);
  double refMean = test::meanLum(ref.img, region), sppmMean = test::meanLum(sppm.img, region);
  std::printf("[%s ball] reference: path %d spp in %.1f s; caustic region %zu px, mean %.4f (sppm %.4f)\n",
              chrome ? "chrome" : "glass", 1 << 15, ref.seconds, region.size(), refMean, sppmMean);
  std::printf("[%s ball] sppm 512 passes x 25k photons: %.2f s, RMSE %.4f; path %d spp: %.2f s, RMSE %.4f\n",
              chrome ? "chrome" : "glass", sppm.seconds, eS, spp, path.seconds, eP);
  // Focused caustics (glass) are where SPPM wins; the light a convex mirror spreads onto the
  // floor is easy for the path tracer too, so there SPPM only has to keep up.
  EXPECT_LT(eS, chrome ? 1.15 * eP : eP);
  EXPECT_NEAR(sppmMean, refMean, 0.1 * refMean);
}

}  // namespace

TEST(LongCaustics, SppmBeatsPathAtEqualTimeGlass) { equalTime(false); }
TEST(LongCaustics, SppmBeatsPathAtEqualTimeChrome) { equalTime(true); }
