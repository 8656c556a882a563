// The grid's build: a grid that cannot fit is refused before it is allocated, and Ctrl-C
// during its first fill ends the build (RenderCancelled) where a refinement runs to its end.
#include <gtest/gtest.h>

#include <cstring>

#include "render/Cancellation.h"
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
