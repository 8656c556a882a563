// The render loop's passes on a CUDA GPU for any per-sample integrator: path and direct by
// path regeneration (regeneratePaths), or, with ENVGI_GPU_STAGES=1, a kernel a stage
// (wavefront/WavePass.h); others (the grid integrator's camera samples) one thread
// a pixel running renderPixel, the CPU executor's body, over its samples of the pass. The
// device scene and whatever else the integrator reads live in the DeviceScene's arena, which
// this executor owns. CUDA-only.
#pragma once

#include <cooperative_groups.h>

#include <algorithm>
#include <cstdlib>
#include <cstring>
#include <memory>
#include <string>

#include "gpu/CudaExecutor.h"
#include "gpu/DeviceScene.h"
#include "wavefront/CudaStageLaunch.cuh"
#include "wavefront/WavePass.h"

namespace envgi::gpu {

template <class Integrator>
__global__ void passKernel(Integrator integ, Camera cam, SampleSequence seq, int s0, int s1, FilmView film,
                           unsigned long long* rays, unsigned long long* dropped) {
  int x = int(blockIdx.x * blockDim.x + threadIdx.x), y = int(blockIdx.y * blockDim.y + threadIdx.y);
  if (x >= cam.width || y >= cam.height) return;
  PixelCounters pc;
  renderPixel(cam, seq, integ, x, y, s0, s1, film, &pc);
  atomicAdd(rays, (unsigned long long)pc.rays);
  if (pc.dropped) atomicAdd(dropped, (unsigned long long)pc.dropped);
}

// Threads a block of regenKernel.
constexpr int kRegenBlock = 128;

// The pass by path regeneration (PixelKernel.h's regeneratePaths): as many threads as the GPU
// holds at once, each taking (pixel, sample) items from counters[2] as its paths end. A warp's
// lanes that need work take consecutive items with one atomic.
template <class Integrator>
__global__ void __launch_bounds__(kRegenBlock, kTracingThreadsPerSM / kRegenBlock)
    regenKernel(Integrator integ, Camera cam, SampleSequence seq, int s0, int s1, FilmView film,
                unsigned long long* counters) {
  namespace cg = cooperative_groups;
  auto fetch = [counters]() -> uint64_t {
    cg::coalesced_group g = cg::coalesced_threads();
    unsigned long long base = 0;
    if (g.thread_rank() == 0) base = atomicAdd(counters + 2, (unsigned long long)g.size());
    return g.shfl(base, 0) + g.thread_rank();
  };
  PixelCounters pc;
  regeneratePaths(cam, seq, integ, s0, s1, film, fetch, &pc);
  atomicAdd(counters, (unsigned long long)pc.rays);
  if (pc.dropped) atomicAdd(counters + 1, (unsigned long long)pc.dropped);
}

// Blocks of kRegenBlock threads of regenKernel<Integrator> that one SM holds at once.
template <class Integrator>
int regenBlocksPerSM() {
  int perSM = 0;
  check(cudaOccupancyMaxActiveBlocksPerMultiprocessor(&perSM, regenKernel<Integrator>, kRegenBlock, 0),
        "sizing the render kernel");
  return perSM;
}

template <class Integrator>
class CudaPassExecutor final : public PassExecutor {
 public:
  // kinds: the shade kinds of the scene's materials, for the stages.
  CudaPassExecutor(std::unique_ptr<DeviceScene> scene, Integrator integ, const Camera& cam, SampleSequence seq,
                   int gpu, bool keepVariance, ShadeKindSet kinds = {})
      : gpu_(gpu), scene_(std::move(scene)), cam_(cam), seq_(seq), integ_(integ), kinds_(kinds) {
    DeviceArena& a = scene_->arena;
    size_t px = size_t(cam_.width) * cam_.height;
    film_.width = cam_.width;
    film_.height = cam_.height;
    film_.sum = a.allocate<Color>(px, "film");
    check(cudaMemset(film_.sum, 0, px * sizeof(Color)), "clearing the film");
    if (keepVariance) {
      film_.sumSqLum = a.allocate<double>(px, "film variance");
      check(cudaMemset(film_.sumSqLum, 0, px * sizeof(double)), "clearing the film");
    }
    if (cam_.filter.hasNegativeLobes()) {
      film_.weightSum = a.allocate<float>(px, "film filter weights");
      check(cudaMemset(film_.weightSum, 0, px * sizeof(float)), "clearing the film");
    }
    counters_ = a.allocate<unsigned long long>(3, "counters");
    check(cudaMemset(counters_, 0, 3 * sizeof(unsigned long long)), "clearing counters");
    if constexpr (RunsByBounce<Integrator>::value) {
      // ENVGI_GPU_STAGES=wide: the shade stages' kernels at up to 128 registers (CudaStageLaunch.cuh).
      const char* st = std::getenv("ENVGI_GPU_STAGES");
      wideShade_ = st && std::strcmp(st, "wide") == 0;
      if (st && (std::strcmp(st, "1") == 0 || wideShade_)) {
        // As many paths as pixels, up to 2^20 (pbrt-v4's wavefront holds 2^20 too).
        const int capacity = int(std::min<size_t>(px, size_t(1) << 20));
        const size_t bytes = layOutWave(0, capacity, px, &waveQueues_, &waveSums_);
        layOutWave(reinterpret_cast<uintptr_t>(a.allocate(bytes, "the wave's queues")), capacity, px, &waveQueues_,
                   &waveSums_);
        return;
      }
      // Path regeneration unless ENVGI_GPU_REGEN=0 asks for one thread a pixel: on an H200 it
      // drew 1.65x the samples a second on the Buddha and 1.45x on the dragon (docs/gpu.md).
      const char* e = std::getenv("ENVGI_GPU_REGEN");
      if (!(e && std::strcmp(e, "0") == 0)) {
        int sms = 0;
        check(cudaDeviceGetAttribute(&sms, cudaDevAttrMultiProcessorCount, gpu_), "sizing the render kernel");
        regenBlocks_ = std::max(1, regenBlocksPerSM<Integrator>() * sms);
      }
    }
  }
  size_t deviceBytes() const { return scene_->arena.bytes(); }
  // A GPU draws about 50 times the CPU's samples a second: 2^28 is about 0.6 s on an H200.
  double maxPassPixelSamples() const override { return double(1 << 28); }

  std::string deviceName() const override {
    return "cuda:" + std::to_string(gpu_) + " (" + gpu::deviceName(gpu_) +
           (regenBlocks_ > 0                ? ", regeneration)"
            : waveQueues_.capacity > 0 ? (wideShade_ ? ", stages, wide shading)" : ", stages)")
                                       : ")");
  }

  void runPass(int s0, int s1, Progress& progress, PassCounters* counters) override {
    if constexpr (RunsByBounce<Integrator>::value) {
      if (waveQueues_.capacity > 0) {
        PixelCounters pc;
        CudaStageLaunch launch{wideShade_};
        runWavePass(launch, WaveContext<Integrator>{integ_, cam_, seq_, film_, WaveRegion{0, 0, cam_.width, cam_.height},
                                                          waveQueues_, waveSums_}, kinds_, s0, s1,
                    &pc);
        counters->rays += pc.rays;
        counters->dropped += pc.dropped;
        progress.add(activePixels() * size_t(s1 - s0));
        return;
      }
    }
    if (regenBlocks_ > 0) {
      if constexpr (RunsByBounce<Integrator>::value) {
        size_t items = size_t(cam_.width) * cam_.height * size_t(s1 - s0);
        int blocks = int(std::min<size_t>(size_t(regenBlocks_), (items + kRegenBlock - 1) / kRegenBlock));
        regenKernel<<<blocks, kRegenBlock>>>(integ_, cam_, seq_, s0, s1, film_, counters_);
      }
    } else {
      dim3 block(16, 8);
      dim3 grid((cam_.width + 15) / 16, (cam_.height + 7) / 8);
      passKernel<<<grid, block>>>(integ_, cam_, seq_, s0, s1, film_, counters_, counters_ + 1);
    }
    check(cudaGetLastError(), "launching the render kernel");
    check(cudaDeviceSynchronize(), "running the render kernel");
    unsigned long long c[3];
    check(cudaMemcpy(c, counters_, sizeof(c), cudaMemcpyDeviceToHost), "reading counters");
    check(cudaMemset(counters_, 0, sizeof(c)), "clearing counters");
    counters->rays += c[0];
    counters->dropped += c[1];
    progress.add(activePixels() * size_t(s1 - s0));
  }

  // A new camera of the same size keeps everything on the device (scene, BVH, a grid) and
  // clears the film; another size needs a new film, so a new executor.
  bool restart(const Camera& cam) override {
    if (cam.width != cam_.width || cam.height != cam_.height) return false;
    if (cam.filter.hasNegativeLobes() != (film_.weightSum != nullptr)) return false;  // a film of another kind
    cam_ = cam;
    size_t px = size_t(cam_.width) * cam_.height;
    check(cudaMemset(film_.sum, 0, px * sizeof(Color)), "clearing the film");
    if (film_.sumSqLum) check(cudaMemset(film_.sumSqLum, 0, px * sizeof(double)), "clearing the film");
    if (film_.weightSum) check(cudaMemset(film_.weightSum, 0, px * sizeof(float)), "clearing the film");
    film_.active = nullptr;
    activeCount_ = 0;
    return true;
  }

  // The mask lives beside the film, allocated on first use; film_.active points at it while a
  // render is adaptive.
  bool setActivePixels(const std::vector<unsigned char>& mask) override {
    size_t px = size_t(cam_.width) * cam_.height;
    if (mask.size() != px) return false;
    if (!activeMask_) activeMask_ = scene_->arena.allocate<unsigned char>(px, "adaptive sampling mask");
    check(cudaMemcpy(activeMask_, mask.data(), px, cudaMemcpyHostToDevice), "uploading the adaptive sampling mask");
    film_.active = activeMask_;
    activeCount_ = mask.size() - size_t(std::count(mask.begin(), mask.end(), (unsigned char)0));
    return true;
  }
  bool keepsVariance() const override { return film_.sumSqLum != nullptr; }

  void readFilm(FilmSums* out) override {
    size_t px = size_t(cam_.width) * cam_.height;
    out->sum.resize(px);
    check(cudaMemcpy(out->sum.data(), film_.sum, px * sizeof(Color), cudaMemcpyDeviceToHost), "reading the film");
    out->sumSqLum.clear();
    if (film_.sumSqLum) {
      out->sumSqLum.resize(px);
      check(cudaMemcpy(out->sumSqLum.data(), film_.sumSqLum, px * sizeof(double), cudaMemcpyDeviceToHost),
            "reading the film");
    }
    out->weightSum.clear();
    if (film_.weightSum) {
      out->weightSum.resize(px);
      check(cudaMemcpy(out->weightSum.data(), film_.weightSum, px * sizeof(float), cudaMemcpyDeviceToHost),
            "reading the film");
    }
  }

 private:
  int gpu_;
  std::unique_ptr<DeviceScene> scene_;
  Camera cam_;
  SampleSequence seq_;
  Integrator integ_;
  FilmView film_;
  // The pixels a pass samples: all of them, or those adaptive sampling leaves on.
  size_t activePixels() const { return film_.active ? activeCount_ : size_t(cam_.width) * cam_.height; }

  unsigned char* activeMask_ = nullptr;     // adaptive sampling's mask on the device, once set
  size_t activeCount_ = 0;                  // its non-zero entries
  unsigned long long* counters_ = nullptr;  // rays, dropped samples, regeneration's next item
  int regenBlocks_ = 0;  // > 0: passes by path regeneration, this many blocks
  ShadeKindSet kinds_;
  WaveQueues waveQueues_;  // capacity > 0: passes by the stages
  bool wideShade_ = false;  // ENVGI_GPU_STAGES=wide
  WaveSums waveSums_;
};

}  // namespace envgi::gpu
