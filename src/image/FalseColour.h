// The false-colour ramp envgi draws errors with (the study's error maps, `envgi image diff`):
// dark blue at 0, then green, yellow and red at 1.
#pragma once

#include <algorithm>
#include <vector>

#include "core/Vec.h"
#include "image/Image.h"

namespace envgi {

inline Color errorRamp(float e) {
  return Color(std::clamp(2.f * e - 0.5f, 0.f, 1.f), std::clamp(e < 0.75f ? 1.6f * e : 4.f * (1.f - e), 0.f, 1.f),
               std::clamp(0.6f - 1.5f * e, 0.f, 1.f));
}

// A pixel's relative error |L(a) - L(ref)| / (L(ref) + 0.05), clamped to [0, 1]: 0.05 keeps black
// reference pixels from dominating.
inline float relativeLuminanceError(const Color& a, const Color& ref) {
  const float la = luminance(a), lr = luminance(ref);
  return std::clamp(std::fabs(la - lr) / (lr + 0.05f), 0.f, 1.f);
}

// Errors in [0, 1], one a pixel, as 8-bit RGB through errorRamp.
inline std::vector<unsigned char> rampRgb(const std::vector<float>& errors) {
  std::vector<unsigned char> rgb(errors.size() * 3);
  for (size_t i = 0; i < errors.size(); ++i) {
    const Color c = errorRamp(errors[i]);
    for (int k = 0; k < 3; ++k) rgb[3 * i + size_t(k)] = (unsigned char)(c[k] * 255.f);
  }
  return rgb;
}

// The 8-bit RGB picture of a's relative error against ref, pixel by pixel.
inline std::vector<unsigned char> errorMapRgb(const Image& a, const Image& ref) {
  std::vector<float> e(size_t(a.width) * size_t(a.height));
  for (int y = 0; y < a.height; ++y)
    for (int x = 0; x < a.width; ++x) e[size_t(y) * size_t(a.width) + size_t(x)] = relativeLuminanceError(a.at(x, y), ref.at(x, y));
  return rampRgb(e);
}

}  // namespace envgi
