// Where a render pass runs. The render loop (Renderer.cpp) owns passes, progress, checkpoints
// and cancellation; an executor owns the film and runs samples [s0, s1) of every pixel on
// its device: the CPU through oneTBB, or a CUDA GPU (src/gpu).
#pragma once

#include <atomic>
#include <string>
#include <vector>

#include "core/Vec.h"
#include "render/Progress.h"
#include "scene/Camera.h"

namespace envgi {

struct PassCounters {
  uint64_t rays = 0;
  uint64_t dropped = 0;
};

// The film read back to the host: per-pixel sums of radiance and of squared luminance.
struct FilmSums {
  std::vector<Color> sum;
  std::vector<double> sumSqLum;  // empty when the executor was not asked to keep it
  // Sums of the filter's weights, for a filter with negative lobes (ReconstructionFilter.h);
  // empty where every sample weighs one, and the pixel is its sum over its sample count.
  std::vector<float> weightSum;
};

class PassExecutor {
 public:
  virtual ~PassExecutor() = default;
  virtual std::string deviceName() const = 0;
  // Adds samples [s0, s1) of every pixel to the film; reports pixel-samples done to progress.
  virtual void runPass(int s0, int s1, Progress& progress, PassCounters* counters) = 0;
  virtual void readFilm(FilmSums* out) = 0;
  // The most samples one pass may take: passes are where checkpoints and Ctrl-C happen.
  virtual int maxPassSize() const { return 64; }
  // The most pixel-samples (pixels x samples) one pass may take: about 5 s of path tracing the
  // bundled Buddha on two cores.
  virtual double maxPassPixelSamples() const { return double(1 << 24); }
  // Starts over with a new camera and an empty film, keeping what does not depend on the
  // camera (photon maps, a grid). False: this executor cannot, make a new one.
  virtual bool restart(const Camera&) { return false; }
  // Adaptive sampling: later passes sample only the pixels whose mask entry is non-zero (one a
  // pixel, row-major). False: this executor samples every pixel in every pass (SPPM).
  virtual bool setActivePixels(const std::vector<unsigned char>& /*mask*/) { return false; }
  // Whether readFilm returns each pixel's sum of squared luminance (adaptive sampling's noise).
  virtual bool keepsVariance() const { return false; }
  // Ctrl-C inside a pass (null: none). An executor that watches it starts no tile once it is
  // set, so that a pass of minutes (one sample of a huge image) stops within a tile's time;
  // cutPass() then says which pixels took the pass. One that does not runs its passes whole.
  virtual void watchCancel(const std::atomic<bool>* /*cancel*/) {}
  // After runPass: null where the pass ran whole; else one entry a pixel (row-major), non-zero
  // where the pixel took every sample of the pass, zero where it took none of them.
  virtual const std::vector<unsigned char>* cutPass() const { return nullptr; }
};

}  // namespace envgi
