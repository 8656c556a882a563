// The wave stages (WaveStages.h, run by WavePass.h) against the per-pixel body (renderPixel):
// a wave holds at most one sample of a pixel and a pass adds its sums at its end, so over the
// GPU's BVH the film's sums agree to the bit, whether the CPU's launcher runs each stage's batch
// form or each stage's function of one index over its queue in any order, as a GPU's threads
// would.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstring>
#include <numeric>
#include <random>
#include <set>
#include <string>
#include <utility>

#include "scene/NameTables.h"
#include "support/SmallKernelScene.h"
#include "wavefront/HostStageLaunch.h"
#include "wavefront/WavePass.h"

using namespace envgi;
using test::Film;
using test::SmallScene;

namespace {

// The whole film, a wave of `capacity` paths at a time.
WaveContext<SampleIntegrator<BvhTracer>> waveContext(const SmallScene& small, HostWave* wave, FilmView film) {
  const Camera& cam = small.scene.view().camera;
  return {small.integrator(),           cam,         small.k.sequence, film, WaveRegion{0, 0, cam.width, cam.height},
          wave->queues,                 wave->sums};
}

// Each stage's function of one index over its queue, in a shuffled order.
struct ShuffledStageLaunch : HostStageLaunch {
  mutable std::mt19937 rng{7};
  template <class Stage>
  void operator()(const Stage& stage, int n, const int* count) const {
    std::vector<int> order(size_t(count ? std::min(n, *count) : n));
    std::iota(order.begin(), order.end(), 0);
    std::shuffle(order.begin(), order.end(), rng);
    for (int i : order) stage(i);
  }
};

// Passes (0, 3) and (3, 8) of every pixel through renderPixel and through the wave stages with
// `capacity` paths a wave: the same sums to the bit (expectSameSums).
void expectRenderPixelsSums(const SmallScene& small, int capacity, const std::string& what) {
  const SampleIntegrator<BvhTracer> integ = small.integrator();
  const Camera& cam = small.scene.view().camera;
  const size_t npix = size_t(cam.width) * cam.height;
  Film a{std::vector<Color>(npix, Color(0.f)), std::vector<double>(npix, 0.0)}, b = a;
  Film c = a;
  PixelCounters ca, cb, cc;
  HostWave wave(capacity, npix);
  HostStageLaunch batches = wave.launch();
  ShuffledStageLaunch shuffled{{nullptr}};
  const ShadeKindSet kinds = ShadeKindSet::of(small.scene.view());
  for (auto [s0, s1] : {std::pair{0, 3}, std::pair{3, 8}}) {
    for (int y = 0; y < cam.height; ++y)
      for (int x = 0; x < cam.width; ++x) renderPixel(cam, small.k.sequence, integ, x, y, s0, s1, a.view(cam), &ca);
    runWavePass(batches, waveContext(small, &wave, b.view(cam)), kinds, s0, s1, &cb);
    runWavePass(shuffled, waveContext(small, &wave, c.view(cam)), kinds, s0, s1, &cc);
    // direct shaded as a path may leave out a ray (expectSameSums); whole, it traces renderPixel's.
    const bool sameRays = integ.type == SampleIntegratorType::Path || !integ.shadesAfterTrace();
    test::expectSameSums(a, b, ca, cb, sameRays, what + " pass " + std::to_string(s0) + ", batch forms");
    test::expectSameSums(a, c, ca, cc, sameRays, what + " pass " + std::to_string(s0) + ", one index at a time");
  }
  double mean = 0.0;
  for (const Color& c : a.sum) mean += c.x + c.y + c.z;
  EXPECT_GT(mean, 0.0) << what << ": an image, not a black film";
}

// The camera round of sample 0 over the whole film (a wave of it): its rays queued, then traced
// and each queued as escaped or by its hit's shade kind.
void traceCameraRound(const SmallScene& small, HostWave* wave) {
  const Camera& cam = small.scene.view().camera;
  const int npix = cam.width * cam.height;
  const auto c = waveContext(small, wave, FilmView{});
  HostStageLaunch launch = wave->launch();
  launch.write(&wave->queues.counts->round, WaveRound{});
  launch(CameraStage<SampleIntegrator<BvhTracer>>{c, 0, 0}, npix, nullptr);
  ASSERT_EQ(wave->queues.counts->round.rays[0], npix);
  launch(ClosestHitStage<SampleIntegrator<BvhTracer>>{c, 0, true}, npix, nullptr);
}

}  // namespace

// path and direct (as the one-bounce path it is with a light and a BSDF sample) on the bundled
// scenes (blend: the blend kind, whose hits have a partner); a wave of the whole film, waves of 100 paths (576 pixels: partial waves, and a pixel's
// samples in different waves), and room for 1000 paths (a wave still takes 576).
TEST(WaveStages, AddsTheSameSamplesAsRenderPixel) {
  for (std::string name : {"teapot-glass", "buddha", "cornell-box", "bunny-sunrise", "sun-and-sky", "blend"})
    for (IntegratorType type : {IntegratorType::Path, IntegratorType::Direct}) {
      SmallScene small(name, type);
      for (int capacity : {24 * 24, 100, 1000})
        expectRenderPixelsSums(small, capacity, name + (type == IntegratorType::Path ? " path" : " direct") +
                                                    " capacity " + std::to_string(capacity));
    }
}

// direct under each of the study's strategies: as a one-bounce path where it takes at most one
// light and one BSDF sample, whole (DirectSampleStage) for the collapsed map at every point
// (`points`) and for several samples of a kind.
TEST(WaveStages, DirectUnderEveryStrategyAddsRenderPixelsSums) {
  int whole = 0;
  for (const StrategyName& s : kStrategyNames) {
    SmallScene small("buddha", IntegratorType::Direct, s.name);
    whole += !small.integrator().shadesAfterTrace();
    expectRenderPixelsSums(small, 100, std::string("direct ") + s.name);
  }
  EXPECT_EQ(whole, 1) << "points, the collapsed map at every point, is the one strategy that is no path";
  SmallScene several("buddha", IntegratorType::Direct);
  several.k.direct.emitterSamples = 3;
  several.k.direct.bsdfSamples = 2;
  ASSERT_FALSE(several.integrator().shadesAfterTrace());
  expectRenderPixelsSums(several, 100, "direct with 3 light and 2 BSDF samples");
}

// A round's hits go to the queue of their material's shade kind and to no other, so a shade
// stage (and a GPU kernel) of one kind is handed only its own type: TypedParts' promise.
TEST(WaveStages, HitsAreQueuedByTheirMaterialsShadeKind) {
  SmallScene small("teapot-glass", IntegratorType::Path);
  const Camera& cam = small.scene.view().camera;
  const size_t npix = size_t(cam.width) * cam.height;
  HostWave wave(int(npix), npix);
  traceCameraRound(small, &wave);
  const WaveQueues& q = wave.queues;
  const SceneView& sc = small.scene.view();
  std::set<int> seen;
  int queued = q.counts->round.escaped;
  for (int kind = 0; kind < kShadeKinds; ++kind)
    for (int i = 0; i < q.counts->round.kinds[kind]; ++i) {
      const int slot = q.kindQueue(kind)[i];
      EXPECT_EQ(shadeKindOf(sc.bsdfs[sc.bsdfIndexAt(q.hit[slot])]), kind);
      seen.insert(kind);
      ++queued;
    }
  EXPECT_EQ(queued, int(npix)) << "every ray is queued once";
  EXPECT_GE(seen.size(), 2u) << "teapot-glass's glass and its floor are of two kinds";
}

// The kinds a scene launches a shade stage for: every kind its camera rays' hits are queued
// under (else those hits would go unshaded), and on the blend scene not the kinds of the blends'
// members alone (a GPU kernel launched on an empty queue each round).
TEST(WaveStages, AShadeStageRunsForEachKindAHitNeeds) {
  for (std::string name : {"blend", "teapot-glass", "buddha", "cornell-box"}) {
    SmallScene small(name, IntegratorType::Path);
    const ShadeKindSet kinds = ShadeKindSet::of(small.scene.view());
    const Camera& cam = small.scene.view().camera;
    const size_t npix = size_t(cam.width) * cam.height;
    HostWave wave(int(npix), npix);
    traceCameraRound(small, &wave);
    int used = 0, hitKinds = 0;
    for (int k = 0; k < kShadeKinds; ++k) {
      used += kinds.used[k];
      if (wave.queues.counts->round.kinds[k] == 0) continue;
      ++hitKinds;
      EXPECT_TRUE(kinds.used[k]) << name << ": kind " << k << " has hits and no stage";
    }
    EXPECT_GE(hitKinds, 1) << name;
    bool ofMaterials[kShadeKinds] = {};
    int materials = 0;
    for (const Bsdf& b : small.scene.bsdfs) ofMaterials[shadeKindOf(b)] = true;
    for (bool m : ofMaterials) materials += m;
    if (name == "blend") {
      EXPECT_TRUE(kinds.used[kBlendShadeKind]);
      EXPECT_LT(used, materials) << "the blends' members' own kinds launch nothing";
    }
  }
}
