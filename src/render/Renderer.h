// Renders a scene on the CPU: oneTBB over image tiles, progressive passes of samples, and a
// checkpoint of the image so far, so a long render never loses finished work.
#pragma once

#include <atomic>
#include <functional>
#include <string>

#include "accel/EmbreeAccel.h"
#include "image/Image.h"
#include "scene/Scene.h"

namespace envgi {

struct RenderOptions {
  int spp = -1;             // -1: the scene's sample_count
  int threads = 0;          // 0: all cores
  int tileSize = 16;
  bool progress = true;
  double checkpointSeconds = 60.0;  // write the image so far at most this often (0: never)
  // Called with the mean image of the passes done so far (checkpoints).
  std::function<void(const Image&, int sppDone)> checkpoint;
  const std::atomic<bool>* cancel = nullptr;  // stop after the current pass when set
  // When set, receives the variance of each pixel's mean luminance (for Z-tests between
  // estimators, as Mitsuba's render tests use).
  std::vector<float>* varianceOut = nullptr;
};

struct RenderStats {
  double seconds = 0.0;
  int sppDone = 0;
  uint64_t rays = 0;
  uint64_t nonFiniteSamples = 0;
  bool cancelled = false;
  double raysPerSecond() const { return seconds > 0.0 ? double(rays) / seconds : 0.0; }
};


Image render(const Scene& scene, const EmbreeAccel& accel, const RenderOptions& opts, RenderStats* stats);

}  // namespace envgi
