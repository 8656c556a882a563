// NVIDIA's FLIP image difference (Andersson et al., "FLIP: A Difference Evaluator for
// Alternating Images", HPG 2020; "Visualizing Errors in Rendered High Dynamic Range Images",
// Eurographics 2021): a per-pixel error in [0, 1] of what a viewer sees when flipping between
// two images, from a colour difference after the eye's contrast sensitivity filters and an
// edge-and-point feature difference. HDR-FLIP is the largest LDR-FLIP over a range of exposures
// of the ACES tone curve. Checked against the reference implementation (flip-evaluator).
#pragma once

#include <vector>

#include "image/Image.h"

namespace envgi {

// Pixels per degree of visual angle: FLIP's default viewer, 0.7 m from a 0.7 m wide screen of
// 3840 pixels.
inline constexpr float kFlipDefaultPpd = 67.0206451f;

// LDR-FLIP of test against ref, both linear RGB (clamped to [0, 1]), row-major, one value a pixel.
std::vector<float> flipLdr(const Image& ref, const Image& test, float ppd = kFlipDefaultPpd);

// HDR-FLIP of test against ref, both linear RGB of any range; the exposures span ref's
// luminance from its largest to its median, as the reference implementation chooses them.
struct FlipExposures {
  float start = 0.f, stop = 0.f;
  int count = 0;
};
FlipExposures flipExposures(const Image& ref);
std::vector<float> flipHdr(const Image& ref, const Image& test, float ppd = kFlipDefaultPpd);

// The mean of a FLIP map (FLIP's one-number summary).
double flipMean(const std::vector<float>& map);

}  // namespace envgi
