// pathShade given its first steps done ahead (pathShadeAhead: the interaction and the light's
// 2D draw, which renderTileByBounce works out for a whole round before shading it) against
// pathShade doing them itself: the same light sample, the same next ray and the same sampler
// position, to the bit, at every bounce, on scenes that take each branch (the product's draw,
// an area light's share, glass, a blend's partner, a textured material). With Sobol's draws,
// the light's and the BSDF's pairs are drawn ahead too, at bounceLayout's offsets past the
// sampler (RoundLanes::drawAhead), and pathShade takes them unchecked: they are drawBounce's
// own draws to the bit, and on the buddha a wrong pair put there changes the path.
#include <gtest/gtest.h>

#include <memory>

#include "accel/Bvh.h"
#include "integrators/PathIntegrator.h"
#include "render/Renderer.h"
#include "scene/SceneLoader.h"

using namespace envgi;

namespace {

struct KeepLd {
  LightSampleLd* out;
  ENVGI_HD void operator()(const LightSampleLd& ld, PathState*) const { *out = ld; }
};

void expectSameLd(const LightSampleLd& a, const LightSampleLd& b, const std::string& where) {
  ASSERT_EQ(a.needsRay, b.needsRay) << where;
  if (!a.needsRay) return;
  for (int c = 0; c < 3; ++c) {
    ASSERT_EQ(a.value[c], b.value[c]) << where;
    ASSERT_EQ(a.o[c], b.o[c]) << where;
    ASSERT_EQ(a.d[c], b.d[c]) << where;
  }
  ASSERT_EQ(a.tMax, b.tMax) << where;
}

// smp's 2D draw at dimension dim.
Vec2f drawAt(const Sampler& smp, uint32_t dim) {
  Sampler at = smp;
  at.dim = dim;
  return at.get2D();
}

}  // namespace

TEST(PathIntegrator, ShadingWithItsFirstStepsDoneAheadIsTheSame) {
  for (std::string name : {"buddha", "cornell-box", "teapot-glass", "blend", "textured", "bunny-sunrise"}) {
    Scene scene;
    loadScene(std::string(ENVGI_SOURCE_DIR) + "/scenes/" + name + ".xml", {{"res", "16"}}, scene);
    scene.camera.width = scene.camera.height = 16;
    scene.integrator.type = IntegratorType::Path;
    scene.finalize();
    RenderOptions o;
    o.spp = 4;
    const KernelSettings k = kernelSettings(scene, o);
    Bvh bvh(scene);
    BvhTracer tracer{bvh.view()};
    const SceneView& sc = scene.view();
    int shaded = 0, productDraws = 0, bsdfDrawsTaken = 0;
    const bool sobol = k.sequence.type == SamplerType::Sobol;
    for (int y = 0; y < 16; ++y)
      for (int x = 0; x < 16; ++x)
        for (int s = 0; s < 4; ++s) {
          Sampler smp = sequenceSampler(k.sequence);
          float w;
          PathState st = pathBegin(startCameraSample(sc.camera, smp, x, y, s, &w));
          for (bool going = true; going;) {
            Hit h;
            const bool found = tracer.intersect(st.ray, &h);
            PathState a = st, b = st;
            Sampler sa = smp, sb = smp;
            LightSampleLd lda, ldb;
            const bool ga = pathShade(sc, &a, found, h, sa, k.path, KeepLd{&lda});
            ShadeAhead ahead;
            ProductDrawAhead draw;
            const ShadeAhead* pre = nullptr;
            Vec2f uL;
            if (found && sobol) {
              const BounceLayout layout = bounceLayout(k.path);
              uL = drawAt(smp, smp.dim + layout.light);
              ahead.ub = drawAt(smp, smp.dim + layout.bsdf);
              ahead.bsdfDrawn = true;
              // The layout is where drawBounce draws.
              Sampler sd = smp;
              BsdfScratch textured;
              const BounceDraws u =
                  drawBounce(sc, sc.bsdfAt(sc.interaction(st.ray, h), &textured), k.path, st.depth, sd, nullptr);
              ASSERT_EQ(u.light.uL.x, uL.x) << name;
              ASSERT_EQ(u.light.uL.y, uL.y) << name;
              ASSERT_EQ(u.bsdf.ub.x, ahead.ub.x) << name;
              ASSERT_EQ(u.bsdf.ub.y, ahead.ub.y) << name;
            }
            if (found) {
              productDraws += pathShadeAhead(sc, st, h, smp, k.path, &ahead, &draw, sobol ? &uL : nullptr);
              pre = &ahead;
            }
            if (found && sobol) {
              // A pair that is not the draw, where the BSDF's should be: taken, it moves the path.
              PathState c = st;
              Sampler sc2 = smp;
              ShadeAhead wrong = ahead;
              wrong.ub = Vec2f(0.5f * (ahead.ub.x + 0.37f), 1.f - ahead.ub.y);
              LightSampleLd ldc;
              const bool gc = pathShade(sc, &c, found, h, sc2, k.path, KeepLd{&ldc}, &wrong);
              Sampler sa2 = smp;
              PathState a2 = st;
              const bool ga2 = pathShade(sc, &a2, found, h, sa2, k.path, KeepLd{&ldc});
              bsdfDrawsTaken += gc != ga2 || c.ray.d.x != a2.ray.d.x || c.ray.d.y != a2.ray.d.y;
            }
            const bool gb = pathShade(sc, &b, found, h, sb, k.path, KeepLd{&ldb}, pre);
            const std::string where = name + " pixel " + std::to_string(x) + "," + std::to_string(y) + " depth " +
                                      std::to_string(st.depth);
            ASSERT_EQ(ga, gb) << where;
            ASSERT_EQ(sa.dim, sb.dim) << where;
            expectSameLd(lda, ldb, where);
            for (int c = 0; c < 3; ++c) {
              ASSERT_EQ(a.L[c], b.L[c]) << where;
              ASSERT_EQ(a.beta[c], b.beta[c]) << where;
              ASSERT_EQ(a.ray.o[c], b.ray.o[c]) << where;
              ASSERT_EQ(a.ray.d[c], b.ray.d[c]) << where;
            }
            ASSERT_EQ(a.prevPdf, b.prevPdf) << where;
            ASSERT_EQ(a.depth, b.depth) << where;
            shaded += found;
            st = a, smp = sa, going = ga;
          }
        }
    EXPECT_GT(shaded, 100) << name;
    if (name == "buddha") {
      EXPECT_GT(productDraws, 100) << "buddha's map is drawn by the product strategy";
      ASSERT_TRUE(sobol) << "buddha's ldsampler is Sobol's";
      EXPECT_GT(bsdfDrawsTaken, shaded / 2) << "the BSDF's pair drawn ahead is the one pathShade takes";
    }
  }
}
