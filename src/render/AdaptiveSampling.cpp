#include "render/AdaptiveSampling.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace envgi {

float pixelNoise(const Color& sum, double sumSqLum, int n) {
  if (n < 2) return 0.f;
  double mean = double(luminance(sum)) / n;
  // The samples' variance (n - 1 in the denominator), then the variance of their mean.
  double var = std::max(0.0, (sumSqLum / n - mean * mean) * n / (n - 1));
  double stdErr = std::sqrt(var / n);
  return float(stdErr / (1e-4 + std::sqrt(std::max(mean, 0.0))));
}

size_t updateActivePixels(const std::vector<Color>& sum, const std::vector<double>& sumSqLum,
                          const std::vector<int>& samples, int width, int height, float threshold, int radius,
                          std::vector<unsigned char>* active) {
  const size_t px = size_t(width) * size_t(height);
  if (sum.size() != px || sumSqLum.size() != px || samples.size() != px || active->size() != px)
    throw std::invalid_argument("adaptive sampling: the film, the sample counts and the mask differ in size");
  std::vector<unsigned char> noisy(px, 0);
  for (size_t i = 0; i < px; ++i)
    noisy[i] = (*active)[i] && !(pixelNoise(sum[i], sumSqLum[i], samples[i]) < threshold);
  // A separable dilation of the noisy pixels: rows, then columns.
  std::vector<unsigned char> rows(px, 0);
  for (int y = 0; y < height; ++y)
    for (int x = 0; x < width; ++x) {
      unsigned char any = 0;
      for (int dx = std::max(0, x - radius); dx <= std::min(width - 1, x + radius) && !any; ++dx)
        any = noisy[size_t(y) * width + dx];
      rows[size_t(y) * width + x] = any;
    }
  size_t left = 0;
  for (int y = 0; y < height; ++y)
    for (int x = 0; x < width; ++x) {
      size_t i = size_t(y) * width + x;
      if (!(*active)[i]) continue;
      unsigned char any = 0;
      for (int dy = std::max(0, y - radius); dy <= std::min(height - 1, y + radius) && !any; ++dy)
        any = rows[size_t(dy) * width + x];
      (*active)[i] = any;
      left += any;
    }
  return left;
}

}  // namespace envgi
