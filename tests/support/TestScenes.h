// Small scenes built in code for integrator tests.
#pragma once

#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "accel/EmbreeAccel.h"
#include "render/Renderer.h"
#include "scene/Scene.h"

namespace envgi::test {

// Mitsuba's checkerboard texture of two grey levels: color0 where u and v are in the same half.
inline Texture checkerboard(float color0, float color1) {
  Texture t;
  t.params.type = TextureType::Checkerboard;
  t.params.color0 = Color(color0);
  t.params.color1 = Color(color1);
  return t;
}

// A binomial share k / n within 4.5 standard deviations of p.
inline void expectShare(int k, int n, double p, const char* what) {
  EXPECT_NEAR(double(k) / n, p, 4.5 * std::sqrt(p * (1.0 - p) / n) + 1e-9) << what;
}

// A sphere of radius 1 at the origin seen by a camera on +z, under a constant environment;
// `texture`, where given, is the scene's texture 0 (for b's texture indices).
inline std::unique_ptr<Scene> furnaceScene(const Bsdf& b, int res, int spp, const Texture* texture = nullptr) {
  auto s = std::make_unique<Scene>();
  s->bsdfs.push_back(b);
  if (texture) s->textures.push_back(*texture);
  s->spheres.push_back({Vec3f(0.f), 1.f, false});
  s->shapes.push_back({true, 0, 0, false, Color(0.f)});
  s->env = std::make_unique<EnvironmentMap>(EnvironmentMap::constant(Color(1.f)));
  s->camera.toWorld = lookAt(Vec3f(0, 0, 4), Vec3f(0, 0, 0), Vec3f(0, 1, 0));
  s->camera.width = s->camera.height = res;
  s->camera.tanHalfX = s->camera.tanHalfY = std::tan(0.5f * 35.f * kPi / 180.f);
  s->camera.filter = makeFilter(FilterType::Box);
  s->sampler.sampleCount = spp;
  s->sampler.type = SamplerType::Sobol;
  s->integrator.type = IntegratorType::Path;
  s->integrator.path.maxDepth = 64;
  s->finalize();
  return s;
}

// A sphere of radius 1 resting on a square floor of half-size `half` (facing +y), lit by
// `sky`, seen by a square camera of `res` pixels with a box filter.
inline std::unique_ptr<Scene> sphereOnFloor(const Bsdf& floor, const Bsdf& ball, float half, Image sky, Vec3f eye,
                                            Vec3f target, int res, float fovDeg) {
  auto s = std::make_unique<Scene>();
  s->bsdfs = {floor, ball};
  TriangleMesh plane = makeRectangle();
  plane.transform(scale(Vec3f(half)));
  plane.transform(rotate(Vec3f(1, 0, 0), -90.f));
  s->meshes.push_back(plane);
  s->shapes.push_back({false, 0, 0, false, Color(0.f)});
  s->spheres.push_back({Vec3f(0.f, 1.f, 0.f), 1.f, false});
  s->shapes.push_back({true, 0, 1, false, Color(0.f)});
  s->env = std::make_unique<EnvironmentMap>(std::move(sky), EnvironmentMapOptions{});
  s->camera.toWorld = lookAt(eye, target, Vec3f(0, 1, 0));
  s->camera.width = s->camera.height = res;
  s->camera.tanHalfX = s->camera.tanHalfY = std::tan(0.5f * fovDeg * kPi / 180.f);
  s->camera.filter = makeFilter(FilterType::Box);
  s->finalize();
  return s;
}

// The scene finalized and rendered on the CPU, with no non-finite samples.
inline Image renderedImage(Scene& s) {
  s.finalize();
  EmbreeAccel accel(s);
  RenderOptions o;
  o.progress = false;
  RenderStats st;
  Image img = render(s, accel, o, &st);
  EXPECT_EQ(st.nonFiniteSamples, 0u);
  return img;
}

// The mean of renderedImage's pixels' luminance.
inline double renderedMean(Scene& s) {
  Image img = renderedImage(s);
  double sum = 0.0;
  for (int y = 0; y < img.height; ++y)
    for (int x = 0; x < img.width; ++x) sum += img.at(x, y).y;
  return sum / (double(img.width) * img.height);
}

// The same, rendered by `type` with spp samples a pixel (passes for sppm), with photon maps and
// grids small enough for a unit test.
inline double renderedMean(Scene& s, IntegratorType type, int spp) {
  s.integrator.type = type;
  s.sampler.sampleCount = spp;
  s.sampler.type = SamplerType::Sobol;
  s.integrator.photon.globalPhotons = s.integrator.photon.causticPhotons = 20000;
  s.integrator.sppm.photonCount = 20000;
  s.integrator.sppm.passes = spp;
  s.integrator.grid.resolution = 8;
  s.integrator.grid.gatherRays = 64;
  s.integrator.grid.globalPhotons = s.integrator.grid.causticPhotons = 20000;
  return renderedMean(s);
}

// Mean of the pixels whose whole footprint sees the sphere (the four corner rays hit it).
inline double meanOverObject(const Scene& scene, const EmbreeAccel& accel, const Image& img, int* count) {
  const Camera& c = scene.view().camera;
  double sum = 0.0;
  int n = 0;
  for (int y = 0; y < c.height; ++y)
    for (int x = 0; x < c.width; ++x) {
      bool inside = true;
      for (float dy : {-0.5f, 1.5f})
        for (float dx : {-0.5f, 1.5f}) {
          Hit h;
          inside = inside && accel.intersect(c.generateRay(x + dx, y + dy), &h);
        }
      if (!inside) continue;
      sum += img.at(x, y).y;
      ++n;
    }
  *count = n;
  return n > 0 ? sum / n : 0.0;
}

// Luminance means over the image's quadrants (row-major: top left, top right, bottom left,
// bottom right), for images of even size.
inline std::vector<double> quadrantMeans(const Image& img) {
  std::vector<double> m(4, 0.0);
  const int hw = img.width / 2, hh = img.height / 2;
  for (int y = 0; y < 2 * hh; ++y)
    for (int x = 0; x < 2 * hw; ++x) m[size_t(2 * (y / hh) + x / hw)] += luminance(img.at(x, y));
  for (double& v : m) v /= double(hw) * hh;
  return m;
}

}  // namespace envgi::test
