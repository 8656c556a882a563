// drawBounce takes a bounce's draws at bounceLayout's offsets past the sampler's position, with
// every sampler, with and without a light sample, before and after roulette begins: the offsets
// a batch of the same draws reads (the CPU's shade stages' lanes) are drawBounce's own.
#include <gtest/gtest.h>

#include "integrators/PathIntegrator.h"
#include "render/Renderer.h"
#include "scene/SceneLoader.h"

using namespace envgi;

namespace {

// smp's 2D draw at dimension dim (at or past its position), as a sampler stepped there draws it.
Vec2f drawAt(const Sampler& smp, uint32_t dim) {
  Sampler at = smp;
  at.skipTo(dim);
  return at.get2D();
}
float draw1DAt(const Sampler& smp, uint32_t dim) {
  Sampler at = smp;
  at.skipTo(dim);
  return at.get1D();
}

}  // namespace

TEST(BounceLayout, DrawBounceDrawsAtTheLayoutsOffsets) {
  Scene scene;
  loadScene(std::string(ENVGI_SOURCE_DIR) + "/scenes/cornell-box.xml", {{"res", "16"}}, scene);
  scene.finalize();
  const SceneView& sc = scene.view();
  ASSERT_LT(sc.envSelectProb(), 1.f) << "a second light: the area light's pair is drawn";
  // A material that reads uc beside its pair, and one that does not, from the bundled scenes.
  std::vector<Bsdf> materials;
  for (std::string name : {"bunny-sunrise", "teapot-glass", "principled", "blend"}) {
    Scene other;
    loadScene(std::string(ENVGI_SOURCE_DIR) + "/scenes/" + name + ".xml", {{"res", "16"}}, other);
    other.finalize();
    materials.insert(materials.end(), other.bsdfs.begin(), other.bsdfs.end());
  }
  int readsUc = -1, noUc = -1;
  for (int i = 0; i < int(materials.size()); ++i) (bsdfReadsUcBesideU(materials[i]) ? readsUc : noUc) = i;
  ASSERT_GE(readsUc, 0);
  ASSERT_GE(noUc, 0);
  int checked = 0;
  for (SamplerType type : {SamplerType::Independent, SamplerType::Stratified, SamplerType::Sobol})
    for (bool light : {true, false})
      for (int depth : {1, 3, 7}) {
        PathParams pp;
        pp.lightSample = light;
        pp.rrDepth = 3;
        const BounceLayout at = bounceLayout(pp);
        for (int m : {readsUc, noUc}) {
          for (uint32_t s = 0; s < 16; ++s) {
            Sampler smp;
            smp.type = type;
            smp.spp = 16;
            smp.start(uint64_t(s) * 7919u + 11u, s);
            smp.skipTo(3 + s % 5);  // a bounce's position past earlier draws
            const Sampler before = smp;
            const BounceDraws u = drawBounce(sc, materials[m], pp, depth, smp, SampledParts{sc});
            const uint32_t base = before.dim;
            const std::string where = "sampler " + std::to_string(int(type)) + " light " + std::to_string(light) +
                                      " depth " + std::to_string(depth) + " material " + std::to_string(m);
            if (light) {
              const Vec2f l = drawAt(before, base + at.light);
              EXPECT_TRUE(l.x == u.light.uL.x && l.y == u.light.uL.y) << where;
              const Vec2f l2 = drawAt(before, base + LightDrawLayout::second);
              EXPECT_TRUE(l2.x == u.light.uL2.x && l2.y == u.light.uL2.y) << where;
            }
            const Vec2f b = drawAt(before, base + at.bsdf);
            EXPECT_TRUE(b.x == u.bsdf.ub.x && b.y == u.bsdf.ub.y) << where;
            if (m == readsUc) {
              EXPECT_EQ(u.bsdf.uc, draw1DAt(before, base + at.bsdf - BsdfDrawLayout::pair)) << where;
            }
            if (depth >= pp.rrDepth) {
              EXPECT_EQ(u.rr, draw1DAt(before, base + at.roulette)) << where;
              EXPECT_EQ(smp.dim, base + at.roulette + 1) << where;
            } else {
              EXPECT_EQ(smp.dim, base + at.roulette) << where;
            }
            ++checked;
          }
        }
      }
  EXPECT_EQ(checked, 3 * 2 * 3 * 2 * 16);
}

// The offsets themselves: the light's pair past the dimension its kind once took, the area
// light's pair, the BSDF's lobe and pair, then roulette; a bounce without a light sample begins
// with the BSDF's draws.
TEST(BounceLayout, OffsetsFollowOneAnother) {
  PathParams pp;
  BounceLayout at = bounceLayout(pp);
  EXPECT_EQ(at.light, 1u);
  EXPECT_EQ(at.bsdf, 6u);
  EXPECT_EQ(at.roulette, 8u);
  pp.lightSample = false;
  at = bounceLayout(pp);
  EXPECT_EQ(at.bsdf, 1u);
  EXPECT_EQ(at.roulette, 3u);
}
