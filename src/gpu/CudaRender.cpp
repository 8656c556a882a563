#include <spdlog/spdlog.h>

#include <stdexcept>

#include "core/PhysicalMemory.h"
#include "gpu/CudaExecutor.h"
#include "render/Renderer.h"

namespace envgi::gpu {

std::string whyNotOnCuda(const Scene&) {
  return "";  // every integrator and grid basis runs there today
}

bool chooseCuda(const std::string& device, const std::string& option, const Scene* scene) {
  if (device != "cpu" && device != "cuda" && device != "auto")
    throw std::runtime_error("unknown device '" + device + "' (cpu, cuda, auto)");
  if (device == "cpu") return false;
  std::string why;
  if (deviceCount(&why) == 0) {
    if (device == "cuda") throw std::runtime_error(option + " cuda: no CUDA device (" + why + ")");
    spdlog::info("device: CPU ({})", why);
    return false;
  }
  if (device == "auto" && scene) why = whyNotOnCuda(*scene);
  if (!why.empty()) spdlog::info("device: CPU ({})", why);
  return why.empty();
}

PreparedRender prepareCudaRender(const Scene& scene, const Bvh& bvh, const EmbreeAccel* accel, RenderOptions opts,
                                 int gpu, size_t* deviceBytes) {
  requireShareable(scene, opts);
  requireFilmFits(scene.view().camera, opts, physicalMemoryBytes());  // its host copy, before the device's
  size_t bytes = 0;
  PreparedRender pr;
  switch (scene.integrator.type) {
    case IntegratorType::Path:
    case IntegratorType::Direct: {
      KernelSettings k = kernelSettings(scene, opts);
      pr.executor = makeCudaExecutor(scene, bvh, k, gpu, opts.keepsVariance(), &bytes);
      pr.spp = k.spp;
      break;
    }
    case IntegratorType::Sppm:
      pr.executor = makeCudaSppmExecutor(scene, bvh, sppmParams(scene), makePhotonEmitter(scene), gpu, &bytes);
      pr.spp = sppmPasses(scene, opts);
      break;
    case IntegratorType::Grid: {
      SequenceAndSpp q = gridSequence(scene, opts);
      if (scene.integrator.grid.basis == "directions") {
        pr.executor = makeCudaDirectionalGridExecutor(scene, bvh, gridExecutorSettings(scene, opts),
                                                      scene.integrator.grid.directions, q.sequence, gpu,
                                                      opts.keepsVariance(), &bytes);
        pr.spp = q.spp;
        break;
      }
      pr.executor = makeCudaGridExecutor(scene, bvh, gridExecutorSettings(scene, opts), q.sequence, gpu,
                                         opts.keepsVariance(), &bytes);
      pr.spp = q.spp;
      break;
    }
    case IntegratorType::Photon: {
      // The final gathers read kd-trees on the CPU: only the photons are traced on the GPU.
      if (!accel) throw std::logic_error("prepareCudaRender: photon needs the CPU's Embree scene");
      opts.photonTracer = makeCudaPhotonTracer(scene, bvh, gpu, scene.integrator.photon.maxDepth);
      spdlog::info("device: photon maps on {}, camera passes on the CPU", opts.photonTracer->deviceName());
      pr = prepareRender(scene, *accel, opts);
      break;
    }
  }
  if (deviceBytes) *deviceBytes = bytes;
  return pr;
}

std::function<PreparedRender(const Scene&, const EmbreeAccel&, const RenderOptions&)> cudaPreparer(int gpu) {
  auto bvh = std::make_shared<std::unique_ptr<Bvh>>();
  return [bvh, gpu](const Scene& s, const EmbreeAccel& accel, const RenderOptions& ro) {
    if (!*bvh) *bvh = std::make_unique<Bvh>(s);
    return prepareCudaRender(s, **bvh, &accel, ro, gpu);
  };
}

}  // namespace envgi::gpu
