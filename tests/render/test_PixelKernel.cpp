// The GPU's path regeneration (regeneratePaths) against the per-pixel body (renderPixel), run
// on the CPU with the GPU's BVH: the same samples, so with one thread taking the items in order
// a fresh film gets the same sums to the bit, for path and direct on glass, a mirror-ish glossy
// object, an area-lit box and a rough conductor under a low sun.
#include <gtest/gtest.h>

#include <cstring>

#include "support/SmallKernelScene.h"

using namespace envgi;
using test::Film;
using test::SmallScene;

TEST(PixelKernel, RegeneratedPathsAddTheSameSamplesAsRenderPixel) {
  for (std::string name : {"teapot-glass", "buddha", "cornell-box", "bunny-sunrise", "sun-and-sky"})
    for (IntegratorType type : {IntegratorType::Path, IntegratorType::Direct}) {
      SmallScene small(name, type);
      const KernelSettings& k = small.k;
      SampleIntegrator<BvhTracer> integ = small.integrator();
      const Camera& cam = small.scene.view().camera;
      size_t npix = size_t(cam.width) * cam.height;
      Film a{std::vector<Color>(npix, Color(0.f)), std::vector<double>(npix, 0.0)}, b = a;
      PixelCounters ca, cb;
      for (int y = 0; y < cam.height; ++y)
        for (int x = 0; x < cam.width; ++x) renderPixel(cam, k.sequence, integ, x, y, 0, 4, a.view(cam), &ca);
      uint64_t next = 0;
      regeneratePaths(cam, k.sequence, integ, 0, 4, b.view(cam), [&] { return next++; }, &cb);
      EXPECT_EQ(next, npix * 4 + 1) << "every item taken once, then one past the end";
      EXPECT_EQ(ca.rays, cb.rays) << name;
      EXPECT_EQ(ca.dropped, cb.dropped) << name;
      EXPECT_EQ(std::memcmp(a.sum.data(), b.sum.data(), npix * sizeof(Color)), 0) << name;
      EXPECT_EQ(std::memcmp(a.sumSq.data(), b.sumSq.data(), npix * sizeof(double)), 0) << name;
      // A second pass adds onto the sums in another order: equal up to float rounding.
      for (int y = 0; y < cam.height; ++y)
        for (int x = 0; x < cam.width; ++x) renderPixel(cam, k.sequence, integ, x, y, 4, 8, a.view(cam), &ca);
      next = 0;
      regeneratePaths(cam, k.sequence, integ, 4, 8, b.view(cam), [&] { return next++; }, &cb);
      EXPECT_EQ(ca.rays, cb.rays) << name;
      for (size_t i = 0; i < npix; ++i)
        for (int c = 0; c < 3; ++c) ASSERT_NEAR(a.sum[i][c], b.sum[i][c], 1e-5f * (1.f + a.sum[i][c])) << name << " " << i;
    }
}
