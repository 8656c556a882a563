// An executor whose camera passes read something built before them (the grid integrator's
// grid, in either basis, on either device) and refined before each pass after the first: the
// passes themselves go to the camera's own executor.
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "render/PassExecutor.h"

namespace envgi {

template <class CameraPasses>
class RefiningExecutor : public PassExecutor {
 public:
  std::string deviceName() const override { return camera_->deviceName(); }
  void runPass(int s0, int s1, Progress& progress, PassCounters* counters) override {
    if (passes_++ > 0) refine();
    camera_->runPass(s0, s1, progress, counters);
  }
  void readFilm(FilmSums* out) override { camera_->readFilm(out); }
  bool restart(const Camera& cam) override { return camera_->restart(cam); }
  bool setActivePixels(const std::vector<unsigned char>& mask) override { return camera_->setActivePixels(mask); }
  bool keepsVariance() const override { return camera_->keepsVariance(); }
  double maxPassPixelSamples() const override { return camera_->maxPassPixelSamples(); }

 protected:
  // More of what the passes read, before a pass (not the first).
  virtual void refine() = 0;
  std::unique_ptr<CameraPasses> camera_;

 private:
  int passes_ = 0;
};

}  // namespace envgi
