// The render loop: progressive passes of samples, progress, a checkpoint of the image so far
// (a long render never loses finished work) and cancellation, over any PassExecutor (the CPU
// through oneTBB, or a CUDA GPU).
#pragma once

#include <atomic>
#include <functional>
#include <memory>
#include <string>

#include "accel/EmbreeAccel.h"
#include "image/Image.h"
#include "integrators/Sppm.h"
#include "render/PassExecutor.h"
#include "render/IlluminationGridBuilder.h"
#include "render/PhotonShooter.h"
#include "render/PixelKernel.h"
#include "scene/Scene.h"

namespace envgi {

// Which tracer the CPU executor uses for path and direct: Embree, or the BVH that the GPU
// traverses (the GPU's kernel bodies run on the CPU, for checking them without a GPU).
enum class CpuTracer { Embree, Bvh };

struct RenderOptions {
  int spp = -1;             // -1: the scene's sample_count
  // Samples [firstSample, sampleEnd) of the spp-sample sequence only (sampleEnd -1: to spp): one
  // share of a render split over tasks, whose film sums (filmOut) add up with the other
  // shares' to the whole render's, up to float rounding.
  int firstSample = 0, sampleEnd = -1;
  FilmSums* filmOut = nullptr;  // when set, receives the film's sums at the end
  int threads = 0;          // 0: all cores
  int tileSize = 16;
  bool progress = true;
  // Where set, the share of the render done (0 to 1), kept current whether or not the bar is
  // drawn: for a caller's own progress display.
  std::atomic<float>* progressFraction = nullptr;
  double checkpointSeconds = 60.0;  // write the image so far at most this often (0: never)
  // Called with the mean image of the passes done so far (checkpoints).
  std::function<void(const Image&, int sppDone)> checkpoint;
  const std::atomic<bool>* cancel = nullptr;  // stop after the current pass when set
  // Stop before a pass that would end past this many seconds of passes, at the rate of those
  // done (0: no limit); the first pass always runs. Cycles' time limit, Mitsuba's timeout.
  double timeLimitSeconds = 0.0;
  // When set, receives the variance of each pixel's mean luminance (for Z-tests between
  // estimators, as Mitsuba's render tests use).
  std::vector<float>* varianceOut = nullptr;
  // Adaptive sampling (AdaptiveSampling.h; Cycles' noise threshold): when > 0, a pixel stops
  // once its noise and its neighbours' is below this, checked after each pass from
  // adaptiveMinSpp samples on. 0: every pixel takes every sample.
  float noiseThreshold = 0.f;
  int adaptiveMinSpp = 16;
  // When set, receives the samples each pixel took (row-major).
  std::vector<int>* samplesOut = nullptr;
  // AOV channels the caller writes beside the image (render's --aov): counted in the film's
  // memory bound (filmBytesPerPixel), since they are as large as the film.
  int aovChannels = 0;
  // Whether executors must keep per-pixel sums of squared luminance.
  bool keepsVariance() const { return varianceOut != nullptr || noiseThreshold > 0.f; }
  CpuTracer cpuTracer = CpuTracer::Embree;
  // Where the photon and grid integrators trace their photon maps; null: the CPU (Embree).
  std::shared_ptr<PhotonBatchTracer> photonTracer;
};

struct RenderStats {
  double seconds = 0.0;
  int sppDone = 0;
  uint64_t rays = 0;
  uint64_t nonFiniteSamples = 0;
  bool cancelled = false;
  bool timeLimited = false;  // stopped by timeLimitSeconds before the requested samples
  uint64_t pixelSamples = 0;  // samples taken over all pixels (fewer than pixels x sppDone when adaptive)
  size_t pixelsStopped = 0;   // pixels that adaptive sampling stopped before the samples asked for
  bool converged = false;     // adaptive sampling stopped every pixel: the render ended early
  // Ctrl-C cut the pass after sppDone at a tile: the pixels that took it whole, at sppAhead.
  size_t pixelsAhead = 0;
  int sppAhead = 0;
  double raysPerSecond() const { return seconds > 0.0 ? double(rays) / seconds : 0.0; }
};

// The path/direct settings the kernels run with, from the scene's integrator settings;
// throws for integrators that have no per-sample kernel (photon, sppm).
KernelSettings kernelSettings(const Scene& scene, const RenderOptions& opts);

// SPPM's options from the scene (each SPPM driver checks them), and the passes to run
// (opts.spp overrides).
SppmParams sppmParams(const Scene& scene);
int sppmPasses(const Scene& scene, const RenderOptions& opts);

// The grid integrator's build settings from the scene (photon tracer: opts.photonTracer), and
// the sample sequence and count its camera passes run.
GridExecutorSettings gridExecutorSettings(const Scene& scene, const RenderOptions& opts);
struct SequenceAndSpp {
  SampleSequence sequence;
  int spp = 0;
};
SequenceAndSpp gridSequence(const Scene& scene, const RenderOptions& opts);

// Logs what an executor counted beyond rays (SPPM's passes, photons and radius).
void logExecutorStats(const PassExecutor& ex);

// An executor for the scene's integrator on the CPU (Embree), with what comes before the
// camera passes done (photon maps, a grid), and the passes it wants (spp, or sppm's passes).
struct PreparedRender {
  std::unique_ptr<PassExecutor> executor;
  int spp = 0;
};
PreparedRender prepareRender(const Scene& scene, const EmbreeAccel& accel, const RenderOptions& opts);

// Renders on the CPU (Embree, or the GPU's BVH by opts.cpuTracer), any integrator.
Image render(const Scene& scene, const EmbreeAccel& accel, const RenderOptions& opts, RenderStats* stats);

// The film's per-pixel means after `samples` samples a pixel.
Image filmMean(const FilmSums& film, int width, int height, int samples);
// The same with each pixel's own count (adaptive sampling); a pixel with none is black.
Image filmMean(const FilmSums& film, int width, int height, const std::vector<int>& samples);

// The host's film at its peak, in bytes a pixel: the executor's sums (squared luminance where
// opts keeps variance, filter weights for a filter with negative lobes, adaptive sampling's
// mask), renderPasses' copy of them, each pixel's sample count and mask, and the mean image.
size_t filmBytesPerPixel(const Camera& cam, const RenderOptions& opts);
// Throws where that film would take more than half of memoryBytes (physicalMemoryBytes()), before
// any of it is allocated: a 32768^2 film (44 GB) otherwise thrashed a 25 GB machine for minutes.
void requireFilmFits(const Camera& cam, const RenderOptions& opts, double memoryBytes);

// Throws where the scene emits no light envgi renders (an emitter it ignored, the log said
// which, would leave a black image); AOVs need none.
void requireLight(const Scene& scene);

// Throws where opts asks for a share of the render (firstSample, sampleEnd) that cannot be one:
// only path's and direct's samples split into shares, and a share takes all of its samples (no
// time limit, no adaptive sampling). Every executor's preparation calls it.
void requireShareable(const Scene& scene, const RenderOptions& opts);

// The loop itself, over an executor that already holds the scene (e.g. a GPU's).
Image renderPasses(PassExecutor& executor, int width, int height, int spp, const RenderOptions& opts,
                   RenderStats* stats);

}  // namespace envgi
