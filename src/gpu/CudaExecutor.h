// The CUDA render backend as the host sees it: plain C++, so the command line and the tests
// compile without nvcc. In a build without CUDA these report that no device exists.
#pragma once

#include <functional>
#include <memory>
#include <string>
#include <utility>

#include "accel/Bvh.h"
#include "integrators/Sppm.h"
#include "render/PassExecutor.h"
#include "render/IlluminationGridBuilder.h"
#include "render/PhotonShooter.h"
#include "render/PixelKernel.h"
#include "render/Renderer.h"

namespace envgi::gpu {

// CUDA devices present; 0 with the reason in *why when there are none, the driver is missing
// or this build has no CUDA.
int deviceCount(std::string* why);
std::string deviceName(int gpu);
// The compute capability (major, minor) of device `gpu`; (0, 0) when it does not exist.
std::pair<int, int> computeCapability(int gpu);

// Whether this build holds machine code for a GPU of compute capability major.minor (else the
// driver JIT-compiles PTX at start-up).
bool hasMachineCodeFor(int major, int minor);

// Threads that path regeneration's and SPPM's kernels keep resident on an SM: __launch_bounds__
// caps their registers so that this many fit (40 a thread). They wait on memory and instruction
// fetch, so more warps beat fewer spills: on an H200, path 420 -> 611 M samples/s and SPPM
// 3.5 -> 2.7 ms a pass. The grid's one-thread-a-pixel kernel lost 20% so capped, and keeps its
// registers (docs/gpu.md).
// The build may set another count (CMake's ENVGI_CUDA_THREADS_PER_SM, for A/B runs).
#ifndef ENVGI_CUDA_THREADS_PER_SM
#define ENVGI_CUDA_THREADS_PER_SM 1536
#endif
constexpr int kTracingThreadsPerSM = ENVGI_CUDA_THREADS_PER_SM;
static_assert(kTracingThreadsPerSM >= 128 && kTracingThreadsPerSM <= 2048 && kTracingThreadsPerSM % 128 == 0,
              "ENVGI_CUDA_THREADS_PER_SM: 128 to 2048, a multiple of the kernels' 128-thread block");

// The path/direct kernel's registers a thread and its resident blocks an SM on device `gpu`
// (path regeneration's launch); zeros without CUDA.
struct KernelOccupancy {
  int registers = 0, blocksPerSM = 0, threadsPerBlock = 0;
};
KernelOccupancy pathKernelOccupancy(int gpu);

// Makes CUDA device `gpu` current, warning once when it needs PTX JIT; throws when it does not exist.
void selectDevice(int gpu);

// Uploads the scene and its BVH to GPU `gpu` and runs path/direct passes there; *deviceBytes
// receives the device memory it holds.
std::unique_ptr<PassExecutor> makeCudaExecutor(const Scene& scene, const Bvh& bvh, const KernelSettings& k, int gpu,
                                               bool keepVariance, size_t* deviceBytes = nullptr);

// Uploads the scene and its BVH and runs SPPM there, one iteration a pass (integrators/Sppm.h's
// steps as kernels); the emitter is the CPU's (render/PhotonShooter).
std::unique_ptr<PassExecutor> makeCudaSppmExecutor(const Scene& scene, const Bvh& bvh, const SppmParams& params,
                                                   const PhotonEmitter& emitter, int gpu, size_t* deviceBytes = nullptr);

// Traces photon-map passes on GPU `gpu` (photons of paths up to maxDepth bounces); the maps
// are then built on the host as the CPU's.
std::shared_ptr<PhotonBatchTracer> makeCudaPhotonTracer(const Scene& scene, const Bvh& bvh, int gpu, int maxDepth);

// The grid integrator: photon maps traced on GPU `gpu` (unless s.photons.tracer says otherwise),
// the grid filled there, camera passes there.
std::unique_ptr<PassExecutor> makeCudaGridExecutor(const Scene& scene, const Bvh& bvh, GridExecutorSettings s,
                                                   SampleSequence seq, int gpu, bool keepVariance,
                                                   size_t* deviceBytes = nullptr);

// The grid integrator in the paper's basis (`basis` = directions): M directions a point, as
// DirectionalGridExecutor on the CPU, with the gather and the camera passes on GPU `gpu`.
std::unique_ptr<PassExecutor> makeCudaDirectionalGridExecutor(const Scene& scene, const Bvh& bvh,
                                                              GridExecutorSettings s, int directions,
                                                              SampleSequence seq, int gpu, bool keepVariance,
                                                              size_t* deviceBytes = nullptr);

// Why the scene's integrator cannot render on a GPU ("" where it can): prepareCudaRender
// refuses it with this, and `--device auto` renders it on the CPU instead.
std::string whyNotOnCuda(const Scene& scene);

// Whether a render asked for on `device` (cpu, cuda or auto) runs on a GPU: cuda without one is
// an error naming `option` (the caller's name for the setting); auto takes one where there is
// one and, given the scene, where it runs there (whyNotOnCuda), logging why not.
bool chooseCuda(const std::string& device, const std::string& option, const Scene* scene);

// The scene's integrator on GPU `gpu`, as prepareRender does it on the CPU: path, direct, sppm
// and grid wholly there; photon traces its maps there and needs accel for the rest.
PreparedRender prepareCudaRender(const Scene& scene, const Bvh& bvh, const EmbreeAccel* accel, RenderOptions opts,
                                 int gpu, size_t* deviceBytes = nullptr);

// prepareCudaRender for a scene whose geometry never changes (the viewer): the BVH is built on
// the first call and kept.
std::function<PreparedRender(const Scene&, const EmbreeAccel&, const RenderOptions&)> cudaPreparer(int gpu);

}  // namespace envgi::gpu
