// A wave of paths in flight and the queues between its stages (WaveStages.h), as plain pointers
// that host and device code index alike: a slot per path of the wave, and for each queue an
// array of slots and its count. A stage fills a queue by claiming places with an atomic add, so
// the order within a queue is any; every result is kept by slot, so it does not depend on it.
#pragma once

#include <type_traits>

#include "core/Atomic.h"
#include "integrators/PathIntegrator.h"
#include "materials/ShadeKind.h"
#include "wavefront/FilmView.h"

namespace envgi {

// The queues' counts of a round, together, so that one copy sets them before it and one reads
// them after. rays[parity]: the round's rays, and the next round's.
struct WaveRound {
  int rays[2];
  int escaped, shadows;
  int kinds[kShadeKinds];
};
struct WaveCounts {
  WaveRound round;
  uint32_t dropped;  // samples left out of the sums (acceptedSample), over the pass
  uint64_t rays;     // rays traced inside a stage (DirectSampleStage), over the pass
};

struct WaveQueues {
  int capacity = 0;  // slots; a wave holds at most one sample of a pixel (WaveStages.h)
  // A slot per path.
  PathState* state = nullptr;
  Sampler* sampler = nullptr;
  Hit* hit = nullptr;
  LightSampleLd* ld = nullptr;  // the path's next-event sample of this round
  Color* ldBeta = nullptr;      // and the path's beta when it was drawn
  float* weight = nullptr;      // the filter's weight of the path's sample
  uint32_t* pixel = nullptr;
  unsigned char* going = nullptr;  // whether the path goes on past this round
  // The queues: rays (2 x capacity, by parity), the escaped rays, the hits by shade kind
  // (kShadeKinds x capacity), the shadow rays.
  int* rays = nullptr;
  int* escaped = nullptr;
  int* kinds = nullptr;
  int* shadows = nullptr;
  WaveCounts* counts = nullptr;

  ENVGI_HD int* rayQueue(int parity) const { return rays + size_t(parity) * size_t(capacity); }
  ENVGI_HD int* kindQueue(int kind) const { return kinds + size_t(kind) * size_t(capacity); }
  // Appends slot to the queue q whose count is *count. On the host a wave is one thread's
  // (HostStageLaunch.h), and a locked add would wait for the stores before it to drain.
  ENVGI_HD static void push(int* q, int* count, int slot) {
#if defined(__CUDA_ARCH__)
    q[atomicFetchAddRelaxed(count, 1)] = slot;
#else
    q[(*count)++] = slot;
#endif
  }
};

// The pass's own sums per pixel, added to the film once at its end (as renderPixel adds a
// pixel's samples of a pass), so that a film gets the same sums over any number of passes.
struct WaveSums {
  Color* acc = nullptr;
  double* accSq = nullptr;
  float* accW = nullptr;
};

// Points q and sums into one block at base (host or device memory alike), each array aligned to
// 16 bytes, for `capacity` paths and a film of `pixels`. Returns the block's size in bytes; with
// base 0 it only counts them.
inline size_t layOutWave(uintptr_t base, int capacity, size_t pixels, WaveQueues* q, WaveSums* sums) {
  size_t at = 0;
  auto take = [&](auto** p, size_t n) {
    at = (at + 15) & ~size_t(15);
    *p = reinterpret_cast<std::remove_reference_t<decltype(**p)>*>(base + at);
    at += n * sizeof(**p);
  };
  const size_t c = size_t(capacity);
  q->capacity = capacity;
  take(&q->state, c), take(&q->sampler, c), take(&q->hit, c), take(&q->ld, c), take(&q->ldBeta, c);
  take(&q->weight, c), take(&q->pixel, c), take(&q->going, c);
  take(&q->rays, 2 * c), take(&q->escaped, c), take(&q->kinds, kShadeKinds * c), take(&q->shadows, c);
  take(&q->counts, 1);
  take(&sums->acc, pixels), take(&sums->accSq, pixels), take(&sums->accW, pixels);
  return at;
}

}  // namespace envgi
