// The wave stages' launcher on the CPU (WavePass.h's Launch): a stage over chunks of its queue
// under oneTBB, the queues in host memory.
#pragma once

#include <tbb/parallel_for.h>

#include <algorithm>
#include <cstring>
#include <vector>

#include "wavefront/WaveStages.h"

namespace envgi {

struct HostStageLaunch {
  int grain = 256;  // indices a task
  template <class Stage>
  void operator()(const Stage& stage, int n, const int* count) const {
    const int m = count ? std::min(n, *count) : n;
    tbb::parallel_for(tbb::blocked_range<int>(0, m, size_t(grain)), [&](const tbb::blocked_range<int>& r) {
      for (int i = r.begin(); i != r.end(); ++i) stage(i);
    });
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

// A wave's slots, queues and sums in host memory.
class HostWave {
 public:
  HostWave(int capacity, size_t pixels) {
    const size_t bytes = layOutWave(0, capacity, pixels, &queues, &sums);
    block_.resize((bytes + 15) / 16);
    layOutWave(reinterpret_cast<uintptr_t>(block_.data()), capacity, pixels, &queues, &sums);
  }
  WaveQueues queues;
  WaveSums sums;

 private:
  struct alignas(16) Chunk {
    unsigned char bytes[16];
  };
  std::vector<Chunk> block_;
};

}  // namespace envgi
