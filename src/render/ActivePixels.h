// Adaptive sampling's bookkeeping between passes, shared by the render loop (renderPasses) and
// the viewer: each pixel's samples so far, the mask of those still sampling, and the check that
// stops converged pixels (AdaptiveSampling.h). When to check stays with the caller.
#pragma once

#include <cstdint>
#include <vector>

#include "render/PassExecutor.h"

namespace envgi {

class ActivePixels {
 public:
  // Every pixel active with no samples; threshold 0 turns adaptive sampling off (every pixel
  // takes every pass's samples).
  ActivePixels(int width, int height, float threshold);

  // Hands the mask to ex. False where adaptive sampling is off or ex samples every pixel each
  // pass (SPPM); throws std::logic_error where ex can mask pixels but keeps no variance.
  bool attach(PassExecutor& ex);
  bool adaptive() const { return adaptive_; }

  // Samples [s0, s1) of every active pixel were taken.
  void passDone(int s0, int s1);
  // Samples [s0, s1) of the active pixels where took is non-zero (a pass cut by Ctrl-C,
  // PassExecutor::cutPass); returns how many pixels that is.
  size_t passDone(int s0, int s1, const std::vector<unsigned char>& took);
  // Reads ex's film into *film, stops the pixels that converged with their neighbours, and hands
  // ex the new mask unless none is left. Returns the pixels still sampling.
  size_t update(PassExecutor& ex, FilmSums* film);

  const std::vector<int>& samples() const { return samples_; }
  size_t activeCount() const { return activeCount_; }
  size_t pixelCount() const { return samples_.size(); }
  bool converged() const { return adaptive_ && activeCount_ == 0; }
  uint64_t pixelSamples() const { return pixelSamples_; }  // samples taken, all pixels together
  double meanSamples() const;

 private:
  int width_, height_;
  float threshold_;
  bool adaptive_ = false;
  std::vector<int> samples_;
  std::vector<unsigned char> active_;
  size_t activeCount_;
  uint64_t pixelSamples_ = 0;
};

}  // namespace envgi
