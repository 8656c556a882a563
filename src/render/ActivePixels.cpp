#include "render/ActivePixels.h"

#include <stdexcept>

#include "render/AdaptiveSampling.h"

namespace envgi {

ActivePixels::ActivePixels(int width, int height, float threshold)
    : width_(width),
      height_(height),
      threshold_(threshold),
      samples_(size_t(width) * size_t(height), 0),
      active_(samples_.size(), 1),
      activeCount_(samples_.size()) {}

bool ActivePixels::attach(PassExecutor& ex) {
  adaptive_ = threshold_ > 0.f && ex.setActivePixels(active_);
  if (adaptive_ && !ex.keepsVariance())
    throw std::logic_error("adaptive sampling: the executor keeps no per-pixel variance (it was made without "
                           "RenderOptions::keepsVariance())");
  return adaptive_;
}

void ActivePixels::passDone(int s0, int s1) {
  for (size_t i = 0; i < samples_.size(); ++i)
    if (active_[i]) samples_[i] += s1 - s0;
  pixelSamples_ += uint64_t(activeCount_) * uint64_t(s1 - s0);
}

size_t ActivePixels::passDone(int s0, int s1, const std::vector<unsigned char>& took) {
  size_t n = 0;
  for (size_t i = 0; i < samples_.size() && i < took.size(); ++i)
    if (active_[i] && took[i]) samples_[i] += s1 - s0, ++n;
  pixelSamples_ += uint64_t(n) * uint64_t(s1 - s0);
  return n;
}

size_t ActivePixels::update(PassExecutor& ex, FilmSums* film) {
  ex.readFilm(film);
  activeCount_ = updateActivePixels(film->sum, film->sumSqLum, samples_, width_, height_, threshold_, 1, &active_);
  if (activeCount_ > 0) ex.setActivePixels(active_);
  return activeCount_;
}

double ActivePixels::meanSamples() const {
  double sum = 0.0;
  for (int n : samples_) sum += n;
  return samples_.empty() ? 0.0 : sum / double(samples_.size());
}

}  // namespace envgi
