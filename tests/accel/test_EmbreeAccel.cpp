// Embree's 16-wide packets (EmbreeAccel::intersectCoherent) and its stream calls (intersectMany,
// occludedMany) against its one-ray calls on the same rays: the same hits (t to an ulp or two)
// and the same shadow answers, for camera rays and for scattered ones, through masked surfaces,
// with rays Embree cannot take and counts that are not a multiple of 16 or of the stream's chunk.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <vector>

#include "accel/EmbreeAccel.h"
#include "sampling/Pcg32.h"
#include "sampling/Warp.h"
#include "scene/SceneLoader.h"

using namespace envgi;

namespace {

// Rays a renderer makes: camera rays of neighbouring pixels, then rays from random points of the
// scene's bounds in random directions, and a few that Embree's precondition turns away.
std::vector<Ray> raysFor(const SceneView& sc, int n, uint64_t seed) {
  Pcg32 rng(seed, 3u);
  std::vector<Ray> rays;
  for (int i = 0; i < n / 2; ++i)
    rays.push_back(sc.camera.generateRay(float(i % 8) + rng.nextFloat() + 0.3f * sc.camera.width,
                                         float(i / 8) + rng.nextFloat() + 0.3f * sc.camera.height));
  for (int i = n / 2; i < n; ++i) {
    Vec3f o = sc.boundsMin + (sc.boundsMax - sc.boundsMin) * Vec3f(rng.nextFloat(), rng.nextFloat(), rng.nextFloat());
    rays.push_back(Ray{o, sampleUniformSphere(Vec2f(rng.nextFloat(), rng.nextFloat())), INFINITY});
  }
  rays[3].o = Vec3f(3e38f, 0.f, 0.f);
  rays[n - 2].d = Vec3f(NAN, 0.f, 1.f);
  rays[n - 5].tMax = 0.5f * length(sc.boundsMax - sc.boundsMin);
  return rays;
}

// Ray i's answer from packets or streams against the one-ray call's: the same hit, t to an ulp
// or two (Embree's packet kernels divide for it in their own way), u and v to the bit.
void expectOneRayHit(const EmbreeAccel& accel, const std::vector<Ray>& rays, const std::string& name, int i, bool found,
                     const Hit& h, int* hits) {
  Hit one;
  const bool oneFound = accel.intersect(rays[size_t(i)], &one);
  EXPECT_EQ(found, oneFound) << name << " ray " << i << " of " << rays.size();
  if (!found || !oneFound) return;
  ++*hits;
  EXPECT_EQ(h.geomId, one.geomId) << name << " ray " << i;
  EXPECT_EQ(h.primId, one.primId) << name << " ray " << i;
  EXPECT_NEAR(h.t, one.t, 4e-7f * one.t) << name << " ray " << i;
  EXPECT_EQ(std::memcmp(&h.u, &one.u, sizeof(float)), 0) << name << " ray " << i;
  EXPECT_EQ(std::memcmp(&h.v, &one.v, sizeof(float)), 0) << name << " ray " << i;
}

}  // namespace

TEST(EmbreeAccel, PacketsGiveTheOneRayHits) {
  for (std::string name : {"buddha", "mask", "cornell-box", "teapot-glass", "instances"}) {
    Scene scene;
    loadScene(std::string(ENVGI_SOURCE_DIR) + "/scenes/" + name + ".xml", {{"res", "64"}}, scene);
    scene.finalize();
    EmbreeAccel accel(scene);
    for (int n : {1, 16, 37, 256}) {
      std::vector<Ray> rays = raysFor(scene.view(), std::max(n, 8), 17u + uint64_t(n));
      rays.resize(size_t(n));
      std::vector<int> seen(size_t(n), 0);
      int hits = 0;
      accel.intersectCoherent(n, [&](int i) -> const Ray& { return rays[size_t(i)]; },
                              [&](int i, bool found, const Hit& h) {
                                ASSERT_GE(i, 0);
                                ASSERT_LT(i, n);
                                ++seen[size_t(i)];
                                expectOneRayHit(accel, rays, name, i, found, h, &hits);
                              });
      for (int i = 0; i < n; ++i) EXPECT_EQ(seen[size_t(i)], 1) << name << ": each ray answered once, ray " << i;
      if (n >= 37) {
        EXPECT_GT(hits, 0) << name << ": some rays hit";
      }
    }
  }
}

// The mask scene's leaves let rays through where their opacity is low: the packets' filter
// must do so as the one-ray call's does, or the hits above would differ; here, that some of the
// camera rays that reach a masked surface do pass it.
TEST(EmbreeAccel, PacketsPassThroughMasksAsOneRayDoes) {
  Scene scene;
  loadScene(std::string(ENVGI_SOURCE_DIR) + "/scenes/mask.xml", {{"res", "64"}}, scene);
  scene.finalize();
  EmbreeAccel accel(scene);
  const SceneView& sc = scene.view();
  std::vector<Ray> rays;
  for (int y = 0; y < 64; ++y)
    for (int x = 0; x < 64; ++x) rays.push_back(sc.camera.generateRay(float(x) + 0.5f, float(y) + 0.5f));
  int differ = 0;
  accel.intersectCoherent(int(rays.size()), [&](int i) -> const Ray& { return rays[size_t(i)]; },
                          [&](int i, bool found, const Hit& h) {
                            Hit all;
                            const bool surface = accel.intersect(rays[size_t(i)], &all, false);
                            differ += surface && (!found || h.t != all.t);
                          });
  EXPECT_GT(differ, 0) << "no camera ray went through a masked surface";
}

TEST(EmbreeAccel, StreamsGiveTheOneRayAnswers) {
  for (std::string name : {"buddha", "mask", "cornell-box", "teapot-glass", "instances"}) {
    Scene scene;
    loadScene(std::string(ENVGI_SOURCE_DIR) + "/scenes/" + name + ".xml", {{"res", "64"}}, scene);
    scene.finalize();
    EmbreeAccel accel(scene);
    for (int n : {1, 37, 256, 600}) {
      std::vector<Ray> rays = raysFor(scene.view(), std::max(n, 8), 29u + uint64_t(n));
      rays.resize(size_t(n));
      std::vector<int> seen(size_t(n), 0), seenShadow(size_t(n), 0);
      int hits = 0, blockedCount = 0;
      accel.intersectMany(n, [&](int i) -> const Ray& { return rays[size_t(i)]; },
                          [&](int i, bool found, const Hit& h) {
                            ASSERT_GE(i, 0);
                            ASSERT_LT(i, n);
                            ++seen[size_t(i)];
                            expectOneRayHit(accel, rays, name, i, found, h, &hits);
                          });
      // Shadow rays: the same rays, and each cut short of its first hit, which must then pass.
      accel.occludedMany(n, [&](int i) -> const Ray& { return rays[size_t(i)]; },
                         [&](int i, bool blocked) {
                           ASSERT_GE(i, 0);
                           ASSERT_LT(i, n);
                           ++seenShadow[size_t(i)];
                           const Ray& r = rays[size_t(i)];
                           EXPECT_EQ(blocked, accel.occluded(r.o, r.d, r.tMax)) << name << " ray " << i;
                           blockedCount += blocked;
                         });
      for (int i = 0; i < n; ++i) {
        EXPECT_EQ(seen[size_t(i)], 1) << name << ": each ray answered once, ray " << i;
        EXPECT_EQ(seenShadow[size_t(i)], 1) << name << ": each shadow ray answered once, ray " << i;
      }
      if (n >= 37) {
        EXPECT_GT(hits, 0) << name << ": some rays hit";
        EXPECT_GT(blockedCount, 0) << name << ": some shadow rays are blocked";
        EXPECT_LT(blockedCount, n) << name << ": and some are not";
      }
    }
  }
}
