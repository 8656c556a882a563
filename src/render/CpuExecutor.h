// Runs render passes on the CPU: oneTBB over image tiles, each tile a wave through the wave
// stages (wavefront/WavePass.h, in their batch forms: HostStages.h) for path and direct, each
// pixel through renderPixel for the other integrators; both run the integrator bodies the CUDA
// kernels run. Deterministic whatever the thread count (no shared sums), and the same sums
// either way up to Embree's packets' rounding of camera hits.
#pragma once

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/enumerable_thread_specific.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <atomic>
#include <cstdlib>
#include <cstring>
#include <memory>

#include "render/PassExecutor.h"
#include "render/PixelKernel.h"
#include "wavefront/HostStageLaunch.h"
#include "wavefront/WavePass.h"
#include "render/WorkerThreads.h"

namespace envgi {

template <class Integrator>
class CpuExecutor final : public PassExecutor {
 public:
  CpuExecutor(const Camera& cam, SampleSequence seq, Integrator integrate, int threads, bool keepVariance,
              std::string name, int tileSize = 16)
      : cam_(cam), seq_(seq), integrate_(std::move(integrate)),
        arena_(arenaConcurrency(threads)), name_(std::move(name)),
        tile_(tileSize), waves_(tileSize * tileSize, size_t(tileSize) * size_t(tileSize)) {
    film_.sum.assign(size_t(cam.width) * cam.height, Color(0.f));
    if (keepVariance) film_.sumSqLum.assign(film_.sum.size(), 0.0);
    if (cam.filter.hasNegativeLobes()) film_.weightSum.assign(film_.sum.size(), 0.f);
    if constexpr (RunsByBounce<Integrator>::value) {
      // Waves unless ENVGI_CPU_BY_BOUNCE=0 asks for renderPixel (for A/B timings); the film is
      // the same either way but for the last bits of the camera rays' hit distances, which
      // Embree's packets compute in their own way.
      const char* e = std::getenv("ENVGI_CPU_BY_BOUNCE");
      inWaves_ = !(e && std::strcmp(e, "0") == 0);
    }
  }

  // The device alone: the study's results and report group runs by it, whichever body ran.
  std::string deviceName() const override { return name_; }
  // Whether passes run a tile as a wave of the wave stages rather than per pixel.
  bool runsInWaves() const { return inWaves_; }

  void runPass(int s0, int s1, Progress& progress, PassCounters* counters) override {
    int W = cam_.width, H = cam_.height;
    int tilesX = (W + tile_ - 1) / tile_, tilesY = (H + tile_ - 1) / tile_;
    FilmView fv{film_.sum.data(), film_.sumSqLum.empty() ? nullptr : film_.sumSqLum.data(), W, H,
                active_.empty() ? nullptr : active_.data(), film_.weightSum.empty() ? nullptr : film_.weightSum.data()};
    std::atomic<uint64_t> rays{0}, dropped{0};
    // Which tiles ran, where Ctrl-C may cut the pass: a tile once started runs whole, so each
    // pixel takes all of the pass's samples or none.
    std::vector<unsigned char> tileRan(cancel_ ? size_t(tilesX) * size_t(tilesY) : 0, 0);
    std::atomic<bool> cut{false};
    arena_.execute([&] {
      tbb::parallel_for(tbb::blocked_range<int>(0, tilesX * tilesY, 1), [&](const tbb::blocked_range<int>& r) {
        PixelCounters pc;
        for (int t = r.begin(); t < r.end(); ++t) {
          if (cancel_) {
            if (cancel_->load(std::memory_order_relaxed)) {
              cut.store(true, std::memory_order_relaxed);
              continue;
            }
            tileRan[size_t(t)] = 1;
          }
          int x0 = (t % tilesX) * tile_, y0 = (t / tilesX) * tile_;
          int x1 = std::min(W, x0 + tile_), y1 = std::min(H, y0 + tile_);
          // Progress counts the samples taken: the tile's pixels that adaptive sampling left on.
          size_t pixels = 0;
          for (int y = y0; y < y1; ++y)
            for (int x = x0; x < x1; ++x) pixels += fv.takesSamples(size_t(y) * size_t(W) + size_t(x));
          if constexpr (RunsByBounce<Integrator>::value) {
            if (inWaves_) {
              HostWave& wave = waves_.local();
              HostStageLaunch launch = wave.launch();
              const WaveContext<Integrator> c{integrate_, cam_, seq_, fv, WaveRegion{x0, y0, x1 - x0, y1 - y0},
                                              wave.queues, wave.sums};
              runWavePass(launch, c, kinds_, s0, s1, &pc);
              progress.add(pixels * size_t(s1 - s0));
              continue;
            }
          }
          for (int y = y0; y < y1; ++y)
            for (int x = x0; x < x1; ++x) renderPixel(cam_, seq_, integrate_, x, y, s0, s1, fv, &pc);
          progress.add(pixels * size_t(s1 - s0));
        }
        rays += pc.rays;
        dropped += pc.dropped;
      });
    });
    counters->rays += rays.load();
    counters->dropped += dropped.load();
    took_.clear();
    if (cut.load()) {
      took_.assign(size_t(W) * size_t(H), 0);
      for (int t = 0; t < tilesX * tilesY; ++t) {
        if (!tileRan[size_t(t)]) continue;
        int x0 = (t % tilesX) * tile_, y0 = (t / tilesX) * tile_;
        for (int y = y0; y < std::min(H, y0 + tile_); ++y)
          std::fill_n(took_.begin() + std::ptrdiff_t(size_t(y) * size_t(W) + size_t(x0)), std::min(W, x0 + tile_) - x0,
                      (unsigned char)1);
      }
    }
  }

  void watchCancel(const std::atomic<bool>* cancel) override { cancel_ = cancel; }
  const std::vector<unsigned char>* cutPass() const override { return took_.empty() ? nullptr : &took_; }

  void readFilm(FilmSums* out) override { *out = film_; }

  bool restart(const Camera& cam) override {
    cam_ = cam;
    film_.sum.assign(size_t(cam.width) * cam.height, Color(0.f));
    if (!film_.sumSqLum.empty()) film_.sumSqLum.assign(film_.sum.size(), 0.0);
    film_.weightSum.clear();
    if (cam.filter.hasNegativeLobes()) film_.weightSum.assign(film_.sum.size(), 0.f);
    active_.clear();
    took_.clear();
    return true;
  }

  bool setActivePixels(const std::vector<unsigned char>& mask) override {
    if (mask.size() != film_.sum.size()) return false;
    active_ = mask;
    return true;
  }
  bool keepsVariance() const override { return !film_.sumSqLum.empty(); }

 private:
  Camera cam_;
  SampleSequence seq_;
  Integrator integrate_;
  tbb::task_arena arena_;
  std::string name_;
  int tile_;
  bool inWaves_ = false;
  FilmSums film_;
  std::vector<unsigned char> active_;  // empty: every pixel takes samples
  const std::atomic<bool>* cancel_ = nullptr;  // watchCancel's
  std::vector<unsigned char> took_;  // the last pass's pixels where Ctrl-C cut it; else empty
  // Every shade kind: on the CPU a kind no hit needs costs a call on an empty queue.
  ShadeKindSet kinds_ = ShadeKindSet::all();
  // A wave of a tile, one per thread. In memory from the standard allocator, not TBB's scalable
  // one (mmap'd, unseen by LeakSanitizer, which then took each wave's arrays for leaks while the
  // executor lived: a false report in the viewer's fuzzer).
  tbb::enumerable_thread_specific<HostWave, std::allocator<HostWave>> waves_;
};

}  // namespace envgi
