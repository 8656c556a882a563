// The render loop's passes on a CUDA GPU for any per-sample integrator (path/direct, the grid
// integrator's camera samples): one thread a pixel runs renderPixel, the CPU executor's body,
// over its samples of the pass. The device scene and whatever else the integrator reads live
// in the DeviceScene's arena, which this executor owns. CUDA-only.
#pragma once

#include <memory>
#include <string>

#include "gpu/CudaExecutor.h"
#include "gpu/DeviceScene.h"

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

template <class Integrator>
class CudaPassExecutor final : public PassExecutor {
 public:
  CudaPassExecutor(std::unique_ptr<DeviceScene> scene, Integrator integ, const Camera& cam, SampleSequence seq,
                   int gpu, bool keepVariance)
      : gpu_(gpu), scene_(std::move(scene)), cam_(cam), seq_(seq), integ_(integ) {
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
    counters_ = a.allocate<unsigned long long>(2, "counters");
    check(cudaMemset(counters_, 0, 2 * sizeof(unsigned long long)), "clearing counters");
  }
  size_t deviceBytes() const { return scene_->arena.bytes(); }

  std::string deviceName() const override { return "cuda:" + std::to_string(gpu_) + " (" + gpu::deviceName(gpu_) + ")"; }

  void runPass(int s0, int s1, Progress& progress, PassCounters* counters) override {
    dim3 block(16, 8);
    dim3 grid((cam_.width + 15) / 16, (cam_.height + 7) / 8);
    passKernel<<<grid, block>>>(integ_, cam_, seq_, s0, s1, film_, counters_, counters_ + 1);
    check(cudaGetLastError(), "launching the render kernel");
    check(cudaDeviceSynchronize(), "running the render kernel");
    unsigned long long c[2];
    check(cudaMemcpy(c, counters_, sizeof(c), cudaMemcpyDeviceToHost), "reading counters");
    check(cudaMemset(counters_, 0, sizeof(c)), "clearing counters");
    counters->rays += c[0];
    counters->dropped += c[1];
    progress.add(size_t(cam_.width) * cam_.height * size_t(s1 - s0));
  }

  // A new camera of the same size keeps everything on the device (scene, BVH, a grid) and
  // clears the film; another size needs a new film, so a new executor.
  bool restart(const Camera& cam) override {
    if (cam.width != cam_.width || cam.height != cam_.height) return false;
    cam_ = cam;
    size_t px = size_t(cam_.width) * cam_.height;
    check(cudaMemset(film_.sum, 0, px * sizeof(Color)), "clearing the film");
    if (film_.sumSqLum) check(cudaMemset(film_.sumSqLum, 0, px * sizeof(double)), "clearing the film");
    return true;
  }

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
  }

 private:
  int gpu_;
  std::unique_ptr<DeviceScene> scene_;
  Camera cam_;
  SampleSequence seq_;
  Integrator integ_;
  FilmView film_;
  unsigned long long* counters_ = nullptr;
};

}  // namespace envgi::gpu
