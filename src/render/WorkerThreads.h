// How many worker threads a render's oneTBB arena runs, from what the user asked for.
#pragma once

#include <tbb/global_control.h>
#include <tbb/task_arena.h>

#include <memory>
#include <stdexcept>
#include <string>

namespace envgi {

// The most worker threads a render may ask for (Blender's bound too): oneTBB's arena crashed
// (SIGSEGV) or failed to allocate when asked for 10^7 or 10^8.
inline constexpr int kMaxWorkerThreads = 1024;

// An arena's concurrency for `threads` asked: 0 means every core; outside [0, kMaxWorkerThreads]
// it throws.
inline int arenaConcurrency(int threads) {
  if (threads < 0 || threads > kMaxWorkerThreads)
    throw std::runtime_error("threads must be between 0 (every core) and " + std::to_string(kMaxWorkerThreads) +
                             ", not " + std::to_string(threads));
  return threads > 0 ? threads : tbb::this_task_arena::max_concurrency();
}

// Caps every oneTBB loop of the process at `threads` (0: no cap), not only the renders' arenas:
// the photon pass, the map's tables and Embree's BVH build run in oneTBB's default arena, which
// would otherwise take every core whatever --threads says.
inline void limitWorkerThreads(int threads) {
  static std::unique_ptr<tbb::global_control> cap;
  cap.reset();
  if (threads > 0)
    cap = std::make_unique<tbb::global_control>(tbb::global_control::max_allowed_parallelism,
                                                size_t(arenaConcurrency(threads)));
}

}  // namespace envgi
