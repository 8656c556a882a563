// The CUDA backend of a build made without the CUDA toolkit: there is no device to use.
#include "gpu/CudaExecutor.h"

#include <stdexcept>

namespace envgi::gpu {

int deviceCount(std::string* why) {
  if (why) *why = "this envgi was built without CUDA";
  return 0;
}

std::string deviceName(int) { return "none"; }

std::pair<int, int> computeCapability(int) { return {0, 0}; }

bool hasMachineCodeFor(int, int) { return false; }

KernelOccupancy pathKernelOccupancy(int) { return {}; }

void selectDevice(int) { throw std::runtime_error("no CUDA device: this envgi was built without CUDA"); }

std::unique_ptr<PassExecutor> makeCudaSppmExecutor(const Scene&, const Bvh&, const SppmParams&, const PhotonEmitter&, int,
                                                   size_t*) {
  throw std::runtime_error("no CUDA device: this envgi was built without CUDA");
}

std::shared_ptr<PhotonBatchTracer> makeCudaPhotonTracer(const Scene&, const Bvh&, int, int) {
  throw std::runtime_error("no CUDA device: this envgi was built without CUDA");
}

std::unique_ptr<PassExecutor> makeCudaGridExecutor(const Scene&, const Bvh&, GridExecutorSettings, SampleSequence, int,
                                                   bool, size_t*) {
  throw std::runtime_error("no CUDA device: this envgi was built without CUDA");
}

std::unique_ptr<PassExecutor> makeCudaDirectionalGridExecutor(const Scene&, const Bvh&, GridExecutorSettings, int,
                                                              SampleSequence, int, bool, size_t*) {
  throw std::runtime_error("no CUDA device: this envgi was built without CUDA");
}

std::unique_ptr<PassExecutor> makeCudaExecutor(const Scene&, const Bvh&, const KernelSettings&, int, bool, size_t*) {
  throw std::runtime_error("no CUDA device: this envgi was built without CUDA");
}

}  // namespace envgi::gpu
