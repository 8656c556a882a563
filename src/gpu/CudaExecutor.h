// The CUDA render backend as the host sees it: plain C++, so the command line and the tests
// compile without nvcc. In a build without CUDA these report that no device exists.
#pragma once

#include <memory>
#include <string>

#include "accel/Bvh.h"
#include "render/PassExecutor.h"
#include "render/PixelKernel.h"

namespace envgi::gpu {

// CUDA devices present; 0 with the reason in *why when there are none, the driver is missing
// or this build has no CUDA.
int deviceCount(std::string* why);
std::string deviceName(int gpu);

// Uploads the scene and its BVH to GPU `gpu` and runs path/direct passes there; *deviceBytes
// receives the device memory it holds.
std::unique_ptr<PassExecutor> makeCudaExecutor(const Scene& scene, const Bvh& bvh, const KernelSettings& k, int gpu,
                                               bool keepVariance, size_t* deviceBytes = nullptr);

}  // namespace envgi::gpu
