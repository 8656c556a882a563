// The grid's build: a grid that cannot fit is refused before it is allocated, and Ctrl-C
// during its first fill ends the build (RenderCancelled) where a refinement runs to its end.
#include <gtest/gtest.h>

#include <cstring>

#include "render/Cancellation.h"
#include "render/DirectionalGridExecutor.h"
#include "render/GridExecutor.h"
#include "render/Renderer.h"
#include "support/TestScenes.h"

using namespace envgi;

TEST(IlluminationGridBuilder, AGridThatCannotFitIsRefusedBeforeItIsAllocated) {
  try {
    requireGridFits(513, 513, 513, 25.3e9, 512);
    FAIL() << "a 14.6 GB grid on a 25.3 GB machine was accepted";
  } catch (const std::runtime_error& e) {
    EXPECT_STREQ(e.what(),
                 "grid: 513x513x513 points would take 14.6 GB, more than half of this machine's 25.3 GB: lower "
                 "`resolution` (512)");
  }
  EXPECT_NO_THROW(requireGridFits(513, 513, 513, 64e9, 512));
  EXPECT_NO_THROW(requireGridFits(33, 33, 33, 25.3e9, 32));
  EXPECT_NO_THROW(requireGridFits(513, 513, 513, 0.0, 512));  // memory unknown
}

TEST(IlluminationGridBuilder, CancelStopsTheFirstFillButNotARefinement) {
  Bsdf grey;
  Image sky(8, 4);
  for (float& v : sky.rgb) v = 1.f;
  auto scene = test::sphereOnFloor(grey, grey, 3.f, std::move(sky), Vec3f(0, 2.5f, 4.5f), Vec3f(0, 0.5f, 0), 8, 40.f);
  scene->integrator.type = IntegratorType::Grid;
  scene->integrator.grid.resolution = 8;
  scene->integrator.grid.gatherRays = 4;
  scene->integrator.grid.globalPhotons = 2000;
  scene->integrator.grid.causticPhotons = 0;
  scene->finalize();
  EmbreeAccel accel(*scene);
  std::atomic<bool> cancel{true};
  RenderOptions o;
  o.progress = false;
  o.cancel = &cancel;
  GridExecutorSettings ge = gridExecutorSettings(*scene, o);
  ge.photons.tracer = makeCpuPhotonTracer(*scene, accel);
  EXPECT_EQ(ge.cancel, &cancel);
  EXPECT_EQ(ge.photons.cancel, &cancel);
  GridBuild b;
  EXPECT_THROW(buildGridOnCpu(*scene, EmbreeTracer{&accel}, ge, &b), RenderCancelled);
  // The gather alone, over maps shot without the flag: the first fill stops, a refinement
  // (rays after the first) runs to its end on every point.
  ge.photons.cancel = nullptr;
  shootPhotons(*scene, ge.photons, &b.global, &b.caustic, &b.photonStats);
  EXPECT_GT(b.global.size(), 0u);
  b.grid = makeIlluminationGrid(*scene, ge.resolution);
  EXPECT_THROW(gatherIntoGrid(b.grid, *scene, EmbreeTracer{&accel}, b.global, b.caustic, ge, 0, 4, &b.gridStats),
               RenderCancelled);
  ge.refineRays = 4;
  ge.maxGatherRays = 8;
  auto refined = [&](bool cancelRefinement) {
    cancel = false;
    IlluminationGrid g = makeIlluminationGrid(*scene, ge.resolution);
    gatherIntoGrid(g, *scene, EmbreeTracer{&accel}, b.global, b.caustic, ge, 0, 4, nullptr);
    cancel = cancelRefinement;
    gatherIntoGrid(g, *scene, EmbreeTracer{&accel}, b.global, b.caustic, ge, 4, 4, nullptr);
    return g;
  };
  IlluminationGrid whole = refined(false), cancelled = refined(true);
  EXPECT_EQ(cancelled.raysPerPoint(), 8);
  ASSERT_EQ(cancelled.pointCount(), whole.pointCount());
  size_t same = 0;
  for (size_t i = 0; i < whole.pointCount(); ++i)
    same += std::memcmp(&whole.view().sh[i], &cancelled.view().sh[i], sizeof(ShL1)) == 0;
  EXPECT_EQ(same, whole.pointCount());
  // Through render(): the error reaches the caller, with no image.
  EXPECT_THROW(render(*scene, accel, o, nullptr), RenderCancelled);
}

// Points inside a closed surface are found by the share of their rays that meet it from behind,
// whether its material is two-sided (the bundled Buddha's is) or not; once only one-sided backs
// counted, so points inside a two-sided mesh kept the dark inside and the surface beside them
// read it. Both bases: the SH grid and the paper's directions.
TEST(IlluminationGridBuilder, PointsInsideATwoSidedClosedSurfaceAreFound) {
  for (bool twoSided : {false, true}) {
    Bsdf floor, ball;
    ball.twoSided = twoSided;
    Image sky(8, 4);
    for (float& v : sky.rgb) v = 1.f;
    auto scene =
        test::sphereOnFloor(floor, ball, 3.f, std::move(sky), Vec3f(0, 2.5f, 4.5f), Vec3f(0, 0.5f, 0), 8, 40.f);
    scene->integrator.type = IntegratorType::Grid;
    scene->integrator.grid.resolution = 16;
    scene->integrator.grid.gatherRays = 32;
    scene->integrator.grid.maxGatherRays = 32;
    scene->integrator.grid.globalPhotons = 2000;
    scene->integrator.grid.causticPhotons = 0;
    scene->finalize();
    EmbreeAccel accel(*scene);
    RenderOptions o;
    o.progress = false;
    GridExecutorSettings ge = gridExecutorSettings(*scene, o);
    ge.photons.tracer = makeCpuPhotonTracer(*scene, accel);
    GridBuild b;
    buildGridOnCpu(*scene, EmbreeTracer{&accel}, ge, &b);
    SequenceAndSpp q = gridSequence(*scene, o);
    DirectionalGridExecutor<EmbreeTracer> directions(*scene, EmbreeTracer{&accel}, ge, 16, q.sequence, 0, false, 16);
    auto check = [&](const char* basis, size_t n, auto point, const float* weight) {
      int inside = 0, outside = 0;
      for (size_t i = 0; i < n; ++i) {
        const Vec3f p = point(i);
        const float d = length(p - Vec3f(0.f, 1.f, 0.f));
        if (d < 0.8f) {
          ++inside;
          EXPECT_EQ(weight[i], 0.f) << basis << " two-sided " << twoSided << ": inside at distance " << d;
        } else if (d > 1.3f && p.y > 0.3f) {
          ++outside;
          EXPECT_EQ(weight[i], 1.f) << basis << " two-sided " << twoSided << ": outside at distance " << d;
        }
      }
      EXPECT_GT(inside, 20) << basis;
      EXPECT_GT(outside, 500) << basis;
    };
    check("sh", b.grid.pointCount(), [&](size_t i) { return b.grid.point(i); }, b.grid.view().weight);
    const DirectionalGridView& dv = directions.grid().view();
    check("directions", directions.grid().pointCount(), [&](size_t i) { return dv.point(i); }, dv.weight);
  }
}
