// The wave stages' launcher on the CPU (WavePass.h's Launch): a stage over its queue on the
// calling thread, through the stage's batch form where it has one (HostStages.h), else its
// function of one index in a loop. A CPU executor runs a wave a tile on each of its threads, so
// that the wave's slots and queues stay in the thread's caches.
#pragma once

#include <algorithm>
#include <cstring>
#include <vector>

#include "wavefront/HostStages.h"

namespace envgi {

struct HostStageLaunch {
  HostLanes* lanes;
  template <class Stage>
  void operator()(const Stage& stage, int n, const int* count) const {
    const int m = count ? std::min(n, *count) : n;
    if (m == 0) return;
    if constexpr (requires { runOnHost(stage, m, lanes); }) runOnHost(stage, m, lanes);
    else
      for (int i = 0; i < m; ++i) stage(i);
  }
  template <class T>
  void write(T* to, const T& v) const {
    *to = v;
  }
  template <class T>
  T read(const T* from) const {
    return *from;
  }
  void zero(void* p, size_t bytes) const { std::memset(p, 0, bytes); }
};

// A wave's slots, queues and sums in host memory, and the lanes' room for its batch forms.
class HostWave {
 public:
  HostWave(int capacity, size_t pixels) {
    const size_t bytes = layOutWave(0, capacity, pixels, &queues, &sums);
    block_.resize((bytes + 15) / 16);
    layOutWave(reinterpret_cast<uintptr_t>(block_.data()), capacity, pixels, &queues, &sums);
    lanes.resize(size_t(capacity));
  }
  HostWave(const HostWave&) = delete;  // queues point into block_
  HostWave& operator=(const HostWave&) = delete;
  WaveQueues queues;
  WaveSums sums;
  HostLanes lanes;
  HostStageLaunch launch() { return {&lanes}; }

 private:
  struct alignas(16) Chunk {
    unsigned char bytes[16];
  };
  std::vector<Chunk> block_;
};

}  // namespace envgi
