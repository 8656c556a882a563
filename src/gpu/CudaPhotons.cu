// The photon-map pass on a CUDA GPU: one thread a photon runs photon/PhotonTracing.h's
// shootPhoton (the CPU's body) and writes what it stores into its own maxDepth slots; CUB's
// order-keeping DeviceSelect then compacts each sub-batch's global and caustic photons. So the
// maps hold the CPU's photons in the CPU's order, up to traversal rounding and FMA contraction.
#include <cub/device/device_select.cuh>

#include "gpu/CudaExecutor.h"
#include "gpu/DeviceScene.h"
#include "render/PhotonShooter.h"

namespace envgi::gpu {

namespace {

constexpr int kThreads = 128;

__global__ void photonMapKernel(const SceneView* sc, BvhTracer tracer, PhotonEmitter emitter, uint32_t seed,
                                bool aimed, uint64_t first, int count, int maxDepth, int stride, bool wantGlobal,
                                bool wantCaustic, Photon* slots, uint8_t* isGlobal, uint8_t* isCaustic) {
  int i = int(blockIdx.x * blockDim.x + threadIdx.x);
  if (i >= count) return;
  size_t base = size_t(i) * size_t(stride);
  for (int k = 0; k < stride; ++k) isGlobal[base + k] = isCaustic[base + k] = 0;
  int k = 0;
  // tracePhoton stores at bounces 1 .. maxDepth - 1, so maxDepth <= stride slots are enough.
  shootPhoton(*sc, tracer, emitter, seed, first + uint64_t(i), 0, maxDepth, aimed,
              [&](const SurfaceInteraction& si, Vec3f wi, Color pw, bool caustic, int) {
                if (!(caustic ? wantCaustic : wantGlobal)) return;
                slots[base + k] = makePhoton(si, wi, pw);
                (caustic ? isCaustic : isGlobal)[base + k] = 1;
                ++k;
              });
}

class CudaPhotonTracer final : public PhotonBatchTracer {
 public:
  CudaPhotonTracer(const Scene& scene, const Bvh& bvh, int gpu, int maxDepth)
      : gpu_(gpu), scene_(scene, bvh), maxDepth_(std::max(1, maxDepth)) {
    // As many sub-batches a launch as fit ~256 MB of slots (8 at the default depth 16).
    size_t perSub = size_t(kPhotonSubBatch) * size_t(maxDepth_) * sizeof(Photon);
    subs_ = int(std::max<size_t>(1, std::min<size_t>(8, (size_t(256) << 20) / perSub)));
    size_t slots = size_t(subs_) * kPhotonSubBatch * size_t(maxDepth_);
    DeviceArena& a = scene_.arena;
    slots_ = a.allocate<Photon>(slots, "photon slots");
    out_ = a.allocate<Photon>(size_t(kPhotonSubBatch) * size_t(maxDepth_), "photon slots");
    isGlobal_ = a.allocate<uint8_t>(slots, "photon slots");
    isCaustic_ = a.allocate<uint8_t>(slots, "photon slots");
    selected_ = a.allocate<int>(1, "photon slots");
    check(cub::DeviceSelect::Flagged(nullptr, tempBytes_, slots_, isGlobal_, out_, selected_,
                                     kPhotonSubBatch * maxDepth_),
          "sizing the photon compaction");
    temp_ = a.allocate(tempBytes_, "photon compaction scratch");
  }

  std::string deviceName() const override { return "cuda:" + std::to_string(gpu_) + " (" + gpu::deviceName(gpu_) + ")"; }
  int subBatchesPerCall() const override { return subs_; }

  void trace(const PhotonTraceRequest& r, std::vector<PhotonBatch>* out) override {
    if (r.maxDepth > maxDepth_) throw std::runtime_error("photon tracer: made for a smaller max_depth");
    int count = subs_ * kPhotonSubBatch;
    photonMapKernel<<<(count + kThreads - 1) / kThreads, kThreads>>>(
        scene_.deviceView, BvhTracer{scene_.bvh}, r.emitter, r.seed ^ r.stream, r.aimed, r.first, count, r.maxDepth,
        maxDepth_, r.global, r.caustic, slots_, isGlobal_, isCaustic_);
    check(cudaGetLastError(), "launching the photon kernel");
    out->assign(size_t(subs_), PhotonBatch{});
    int perSub = kPhotonSubBatch * maxDepth_;
    for (int b = 0; b < subs_; ++b) {
      size_t offset = size_t(b) * size_t(perSub);
      if (r.global) compact(offset, perSub, isGlobal_, &(*out)[size_t(b)].global);
      if (r.caustic) compact(offset, perSub, isCaustic_, &(*out)[size_t(b)].caustic);
    }
  }

 private:
  // The flagged slots of one sub-batch, in slot order, copied to the host.
  void compact(size_t offset, int n, const uint8_t* flags, std::vector<Photon>* dst) {
    size_t bytes = tempBytes_;
    check(cub::DeviceSelect::Flagged(temp_, bytes, slots_ + offset, flags + offset, out_, selected_, n),
          "compacting photons");
    int selected = 0;
    check(cudaMemcpy(&selected, selected_, sizeof(int), cudaMemcpyDeviceToHost), "tracing photons");
    dst->resize(size_t(selected));
    if (selected > 0)
      check(cudaMemcpy(dst->data(), out_, size_t(selected) * sizeof(Photon), cudaMemcpyDeviceToHost),
            "reading photons");
  }

  int gpu_;
  DeviceScene scene_;
  int maxDepth_;
  int subs_ = 1;
  Photon* slots_ = nullptr;
  Photon* out_ = nullptr;
  uint8_t* isGlobal_ = nullptr;
  uint8_t* isCaustic_ = nullptr;
  int* selected_ = nullptr;
  void* temp_ = nullptr;
  size_t tempBytes_ = 0;
};

}  // namespace

std::shared_ptr<PhotonBatchTracer> makeCudaPhotonTracer(const Scene& scene, const Bvh& bvh, int gpu, int maxDepth) {
  selectDevice(gpu);
  return std::make_shared<CudaPhotonTracer>(scene, bvh, gpu, maxDepth);
}

}  // namespace envgi::gpu
