// Small bundled scenes for the per-sample bodies' tests: a film of sums, and a bundled scene at
// 24 x 24 pixels, 8 spp, with the GPU's BVH over it.
#pragma once

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
  SmallScene(const std::string& name, IntegratorType type) {
    loadScene(std::string(ENVGI_SOURCE_DIR) + "/scenes/" + name + ".xml", {{"res", "24"}}, scene);
    scene.camera.width = scene.camera.height = 24;
    scene.integrator.type = type;
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


}  // namespace envgi::test
