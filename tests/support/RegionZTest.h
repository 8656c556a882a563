// Per-region Z-test of two independent renders of one image (Mitsuba's render tests): the
// difference of region means of luminance over the square root of their summed variances.
#pragma once

#include <algorithm>
#include <cmath>
#include <vector>

#include "image/Image.h"

namespace envgi::test {

// Smallest two-sided p-value over the `region`-pixel squares; *regions receives their count.
// var: per-pixel variance of the mean luminance, as RenderOptions::varianceOut gives it.
inline double minRegionP(const Image& a, const std::vector<float>& varA, const Image& b, const std::vector<float>& varB,
                         int region, int* regions) {
  double minP = 1.0;
  *regions = 0;
  int W = a.width, H = a.height;
  for (int ry = 0; ry + region <= H; ry += region)
    for (int rx = 0; rx + region <= W; rx += region) {
      double m1 = 0, m2 = 0, v1 = 0, v2 = 0;
      for (int y = ry; y < ry + region; ++y)
        for (int x = rx; x < rx + region; ++x) {
          m1 += luminance(a.at(x, y));
          m2 += luminance(b.at(x, y));
          v1 += varA[size_t(y) * W + x];
          v2 += varB[size_t(y) * W + x];
        }
      double n = double(region) * region;
      double z = (m1 - m2) / n / std::sqrt((v1 + v2) / (n * n) + 1e-12);
      minP = std::min(minP, std::erfc(std::fabs(z) / std::sqrt(2.0)));
      ++*regions;
    }
  return minP;
}

}  // namespace envgi::test
