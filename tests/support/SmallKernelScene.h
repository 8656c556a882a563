// Small bundled scenes for the per-sample bodies' tests: a film of sums, and a bundled scene at
// 24 x 24 pixels, 8 spp, with the GPU's BVH over it.
#pragma once

#include <gtest/gtest.h>

#include <cstring>
#include <memory>
#include <string>
#include <vector>

#include "accel/Bvh.h"
#include "render/PixelKernel.h"
#include "render/Renderer.h"
#include "scene/SceneLoader.h"

namespace envgi::test {

struct Film {
  std::vector<Color> sum;
  std::vector<double> sumSq;
  FilmView view(const Camera& cam) { return {sum.data(), sumSq.data(), cam.width, cam.height}; }
};

// A bundled scene at 24 x 24 pixels, 8 spp, with the GPU's BVH over it.
struct SmallScene {
  Scene scene;
  KernelSettings k;
  std::unique_ptr<Bvh> bvh;
  // strategy: a name from kStrategyNames in place of the scene's own, where not empty.
  SmallScene(const std::string& name, IntegratorType type, const std::string& strategy = "") {
    loadScene(std::string(ENVGI_SOURCE_DIR) + "/scenes/" + name + ".xml", {{"res", "24"}}, scene);
    scene.camera.width = scene.camera.height = 24;
    scene.integrator.type = type;
    if (!strategy.empty()) scene.integrator.setStrategy(strategy);
    scene.finalize();
    RenderOptions o;
    o.spp = 8;
    k = kernelSettings(scene, o);
    bvh = std::make_unique<Bvh>(scene);
  }
  SampleIntegrator<BvhTracer> integrator() const {
    return {k.type, k.path, k.direct, &scene.view(), BvhTracer{bvh->view()}};
  }
};

// After a pass, film a (renderPixel's) against film b (another body's over the same samples): the
// same sums to the bit and the same dropped samples; for path the same rays, while direct as a
// path leaves out the BSDF ray of a sample whose weight is zero (a black emitter's), which
// directTrace traces for nothing.
inline void expectSameSums(const Film& a, const Film& b, const PixelCounters& ca, const PixelCounters& cb, bool path,
                           const std::string& what) {
  if (path) {
    EXPECT_EQ(ca.rays, cb.rays) << what;
  } else {
    EXPECT_LE(cb.rays, ca.rays) << what;
    EXPECT_GE(double(cb.rays), 0.99 * double(ca.rays)) << what;
  }
  EXPECT_EQ(ca.dropped, cb.dropped) << what;
  ASSERT_EQ(a.sum.size(), b.sum.size());
  EXPECT_EQ(std::memcmp(a.sum.data(), b.sum.data(), a.sum.size() * sizeof(Color)), 0) << what;
  EXPECT_EQ(std::memcmp(a.sumSq.data(), b.sumSq.data(), a.sumSq.size() * sizeof(double)), 0) << what;
}

}  // namespace envgi::test
