// Stopping a render that is still preparing (the photon maps, the grid's gather): there is no
// finished pass to write yet, so the work ends with this error instead of running on until the
// first pass (a grid of millions of points took many minutes to notice Ctrl-C).
#pragma once

#include <atomic>
#include <stdexcept>

namespace envgi {

struct RenderCancelled : std::runtime_error {
  RenderCancelled() : std::runtime_error("interrupted before the first pass finished: no image written") {}
};

inline bool cancelRequested(const std::atomic<bool>* cancel) {
  return cancel && cancel->load(std::memory_order_relaxed);
}

inline void throwIfCancelled(const std::atomic<bool>* cancel) {
  if (cancelRequested(cancel)) throw RenderCancelled();
}

}  // namespace envgi
