// Image error against a reference, as the paper's Figure 9 and the study report measure it.
#pragma once

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

#include "image/Image.h"

namespace envgi {

struct ImageError {
  double rmse = 0.0;    // root mean squared error over all channels
  double relMse = 0.0;  // mean of (a - r)^2 / (r^2 + 0.01): relative, tolerant of black pixels
  double worstRegionRmse = 0.0;  // the largest RMSE over a 4x4 grid of regions: local error
};

inline ImageError imageError(const Image& a, const Image& ref) {
  if (a.width != ref.width || a.height != ref.height)
    throw std::runtime_error("reference is " + std::to_string(ref.width) + "x" + std::to_string(ref.height) +
                             ", the image " + std::to_string(a.width) + "x" + std::to_string(a.height));
  ImageError e;
  double se = 0.0, rel = 0.0;
  for (size_t i = 0; i < a.rgb.size(); ++i) {
    double d = double(a.rgb[i]) - double(ref.rgb[i]);
    se += d * d;
    rel += d * d / (double(ref.rgb[i]) * ref.rgb[i] + 0.01);
  }
  double n = double(a.rgb.size());
  e.rmse = n > 0 ? std::sqrt(se / n) : 0.0;
  e.relMse = n > 0 ? rel / n : 0.0;
  const int g = 4;
  for (int ry = 0; ry < g; ++ry)
    for (int rx = 0; rx < g; ++rx) {
      int x0 = rx * a.width / g, x1 = (rx + 1) * a.width / g, y0 = ry * a.height / g, y1 = (ry + 1) * a.height / g;
      double s2 = 0.0;
      size_t cnt = 0;
      for (int y = y0; y < y1; ++y)
        for (int x = x0; x < x1; ++x)
          for (int k = 0; k < 3; ++k) {
            double d = double(a.at(x, y)[k]) - double(ref.at(x, y)[k]);
            s2 += d * d;
            ++cnt;
          }
      // A region with a NaN makes the worst region NaN too (std::max would drop it).
      double r = cnt > 0 ? std::sqrt(s2 / double(cnt)) : 0.0;
      if (!std::isnan(e.worstRegionRmse) && !(r <= e.worstRegionRmse)) e.worstRegionRmse = r;
    }
  return e;
}

}  // namespace envgi
