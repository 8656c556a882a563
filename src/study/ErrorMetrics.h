// Image error against a reference, as the paper's Figure 9 and the study report measure it.
#pragma once

#include <stdexcept>
#include <string>

#include "image/Image.h"

namespace envgi {

struct ImageError {
  double rmse = 0.0;    // root mean squared error over all channels
  double relMse = 0.0;  // mean of (a - r)^2 / (r^2 + 0.01): relative, tolerant of black pixels
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
  return e;
}

}  // namespace envgi
