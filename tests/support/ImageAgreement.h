// How closely two renders of the same samples agree (a device against another, a tracer
// against another, same seed): the ratio of image means, the worst region's luminance
// difference relative to the region (plus 0.01 a pixel, so black regions do not blow up), and
// the share of channels equal to 1e-3.
#pragma once

#include <algorithm>
#include <cmath>

#include "image/Image.h"

namespace envgi::test {

struct ImageAgreement {
  double meanRatio = 0.0;    // mean(b) / mean(a)
  double worstRegion = 0.0;  // max over regions of |sum b - sum a| / (sum a + 0.01 n)
  double sameShare = 0.0;    // channels with |b - a| <= 1e-3 (1 + a)
  double meanA = 0.0;
};

inline ImageAgreement compareImages(const Image& a, const Image& b, int region = 8) {
  ImageAgreement r;
  double ma = 0, mb = 0;
  size_t same = 0;
  for (size_t i = 0; i < a.rgb.size(); ++i) {
    ma += a.rgb[i];
    mb += b.rgb[i];
    same += std::fabs(a.rgb[i] - b.rgb[i]) <= 1e-3f * (1.f + a.rgb[i]);
  }
  r.meanA = ma / double(std::max<size_t>(a.rgb.size(), 1));
  r.meanRatio = ma > 0 ? mb / ma : 0.0;
  r.sameShare = double(same) / double(std::max<size_t>(a.rgb.size(), 1));
  for (int ry = 0; ry < a.height; ry += region)
    for (int rx = 0; rx < a.width; rx += region) {
      double sa = 0, sb = 0;
      int n = 0;
      for (int y = ry; y < std::min(a.height, ry + region); ++y)
        for (int x = rx; x < std::min(a.width, rx + region); ++x, ++n) {
          sa += luminance(a.at(x, y));
          sb += luminance(b.at(x, y));
        }
      r.worstRegion = std::max(r.worstRegion, std::fabs(sb - sa) / (sa + 0.01 * n));
    }
  return r;
}

}  // namespace envgi::test
