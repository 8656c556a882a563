// The worker-thread count a render's arena runs: 0 is every core, and counts past the bound are
// refused before oneTBB sees them (its arena crashed when asked for ten million).
#include <gtest/gtest.h>
#include <tbb/parallel_for.h>

#include <chrono>
#include <mutex>
#include <set>
#include <thread>

#include "render/Renderer.h"
#include "render/WorkerThreads.h"
#include "support/TestScenes.h"

using namespace envgi;

TEST(WorkerThreads, ZeroIsEveryCoreAndTooManyIsRefused) {
  EXPECT_EQ(arenaConcurrency(0), tbb::this_task_arena::max_concurrency());
  EXPECT_EQ(arenaConcurrency(3), 3);
  EXPECT_EQ(arenaConcurrency(kMaxWorkerThreads), kMaxWorkerThreads);
  EXPECT_THROW(arenaConcurrency(kMaxWorkerThreads + 1), std::runtime_error);
  EXPECT_THROW(arenaConcurrency(-1), std::runtime_error);
}

// A render asked for ten million threads (a library caller's, past the command line's check)
// ends with the error, not inside oneTBB.
TEST(WorkerThreads, ARenderAskedForTooManyThrows) {
  Bsdf diffuse;
  auto s = test::furnaceScene(diffuse, 8, 1);
  EmbreeAccel accel(*s);
  RenderOptions o;
  o.progress = false;
  o.spp = 1;
  o.threads = 10000000;
  try {
    render(*s, accel, o, nullptr);
    ADD_FAILURE() << "rendered with ten million threads";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("threads must be between 0 (every core) and 1024"), std::string::npos)
        << e.what();
  }
}

// --threads 1 holds every oneTBB loop to one thread, those outside a render's arena too (the
// photon pass, the map's tables, Embree's build), and 0 lifts the cap.
TEST(WorkerThreads, TheCapHoldsLoopsOutsideTheArenas) {
  auto threadsOfALoop = [] {
    std::mutex m;
    std::set<std::thread::id> ids;
    tbb::parallel_for(0, 256, [&](int) {
      std::this_thread::sleep_for(std::chrono::microseconds(200));
      std::lock_guard<std::mutex> lock(m);
      ids.insert(std::this_thread::get_id());
    });
    return ids.size();
  };
  limitWorkerThreads(1);
  EXPECT_EQ(tbb::global_control::active_value(tbb::global_control::max_allowed_parallelism), 1u);
  EXPECT_EQ(threadsOfALoop(), 1u);
  limitWorkerThreads(0);
  EXPECT_EQ(tbb::global_control::active_value(tbb::global_control::max_allowed_parallelism),
            size_t(tbb::this_task_arena::max_concurrency()));
}
