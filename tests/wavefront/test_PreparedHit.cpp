// pathShade given a hit prepared as the CPU's shade stages prepare it (prepareHit: the interaction
// and the light's pair; the product draw taken level by level to its end, and placed as the
// lanes place it; with Sobol's draws, the light's and the BSDF's pairs at bounceLayout's offsets)
// through PreparedParts, against pathShade working each part out itself (SampledParts): the same
// light sample, the same next ray and the same sampler position, to the bit, at every bounce, on
// scenes that take each branch (the product's draw, an area light's share, glass, a blend's
// partner, a textured material). PreparedParts takes the pairs unchecked, and on the buddha a
// wrong pair put there changes the path.
#include <gtest/gtest.h>

#include <memory>

#include "accel/Bvh.h"
#include "render/Renderer.h"
#include "scene/SceneLoader.h"
#include "wavefront/HostStages.h"

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

// A descent begun by prepareHit, taken to its end as walkProductDraws takes it; placed, looked
// up and turned into a direction as the lanes do, where place.
void endDescent(const EnvironmentMapView& env, ProductDescent* a, bool place, DescendedDraw* p) {
  env.product.descend1(a);
  env.product.descend2(a);
  env.product.descend3(a);
  int px, py;
  env.product.descendToPixel(a, &px, &py);
  p->ended = true;
  p->u = a->u, p->nLocal = a->nLocal;
  p->drawn = env.product.descentEnd(*a, &p->uv, &p->pdfUV);
  if (!place || !p->drawn) return;
  p->uv = env.placeInPixel(p->uv, &p->pdfUV);
  p->radiance = env.lookupUV(p->uv);
  p->dir = env.fromLocal(EnvironmentMapView::uvToDir(p->uv));
  p->placed = true;
}

}  // namespace

TEST(PreparedHit, ShadingAPreparedHitIsTheSame) {
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
            PreparedHit prepared;
            ProductDescent descent;
            if (found && sobol) {
              const BounceLayout layout = bounceLayout(k.path);
              prepared.uL = drawAt(smp, smp.dim + layout.light);
              prepared.ub = drawAt(smp, smp.dim + layout.bsdf);
              prepared.bsdfDrawn = true;
            }
            if (found) {
              if (prepareHit(sc, st, h, smp, k.path, sobol, prepared.uL, &prepared, &descent)) {
                endDescent(sc.env, &descent, productDraws % 2 == 1, &prepared.product);
                ++productDraws;
              }
            }
            if (found && sobol) {
              // A pair that is not the draw, where the BSDF's should be: taken, it moves the path.
              PathState c = st;
              Sampler sc2 = smp;
              PreparedHit wrong = prepared;
              wrong.ub = Vec2f(0.5f * (prepared.ub.x + 0.37f), 1.f - prepared.ub.y);
              LightSampleLd ldc;
              const bool gc = pathShade(sc, &c, found, h, sc2, k.path, KeepLd{&ldc}, PreparedParts{sc, wrong});
              Sampler sa2 = smp;
              PathState a2 = st;
              const bool ga2 = pathShade(sc, &a2, found, h, sa2, k.path, KeepLd{&ldc});
              bsdfDrawsTaken += gc != ga2 || c.ray.d.x != a2.ray.d.x || c.ray.d.y != a2.ray.d.y;
            }
            const bool gb = pathShade(sc, &b, found, h, sb, k.path, KeepLd{&ldb}, PreparedParts{sc, prepared});
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
      EXPECT_GT(bsdfDrawsTaken, shaded / 2) << "the BSDF's pair prepared is the one pathShade takes";
    }
  }
}
