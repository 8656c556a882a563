// Adaptive sampling, as Cycles' noise threshold: once a pixel's estimated noise falls below a
// threshold, it stops taking samples, and the passes' work goes to the pixels still noisy.
// Pure functions over the film's sums; the render loop (Renderer.cpp) applies them between
// passes and the executors skip the pixels it masks off (FilmView::takesSamples).
#pragma once

#include <cstdint>
#include <vector>

#include "core/Vec.h"

namespace envgi {

// A pixel's noise after n samples: the standard error of its mean luminance over the square
// root of that mean. The root stands in for a tone curve, so a threshold means about as much
// in the shadows as in the highlights (Cycles normalises its threshold so); the 1e-4 keeps a
// black pixel finite. Zero for n < 2 (no variance yet).
float pixelNoise(const Color& sum, double sumSqLum, int n);

// One check of adaptive sampling after a pass. active holds one entry a pixel (row-major):
// 1 while it takes samples. An active pixel whose noise after samples[i] samples is below
// threshold has converged; a stopped pixel counts as converged. A pixel stops when it and every
// pixel within radius (a (2r+1)^2 window) have converged, so an isolated low estimate (a pixel
// that has not yet met a rare bright path) keeps sampling while its neighbours are noisy.
// Stopping is final: a pixel's samples stay a prefix of its sequence. Returns the pixels that
// are still active.
size_t updateActivePixels(const std::vector<Color>& sum, const std::vector<double>& sumSqLum,
                          const std::vector<int>& samples, int width, int height, float threshold, int radius,
                          std::vector<unsigned char>* active);

}  // namespace envgi
