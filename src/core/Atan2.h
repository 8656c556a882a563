// atan2 as a polynomial: the environment map turns every escaping ray into (u, v) with two
// atan2 calls, and libm's atan2f was 4.5% of a path-traced frame.
#pragma once

#include <cmath>

#include "core/Common.h"

namespace envgi {

// atan2(y, x) within 4e-7 radians (1.7 float ulps of pi) of the exact value (test_Atan2.cpp),
// with std::atan2's quadrants and signed zeros except at (±0, -0), where it gives ±0, not ±pi.
// The core is atan(a) on [0, 1] as a + a^3 P(a^2), P a degree-6 minimax fit (1.1e-7 in float);
// the other octants follow from atan(1/a) = pi/2 - atan(a) and atan2's reflections.
ENVGI_INLINE float polyAtan2(float y, float x) {
  float ax = std::fabs(x), ay = std::fabs(y);
  float hi = ax > ay ? ax : ay, lo = ax > ay ? ay : ax;
  // Divided whatever hi is, then chosen: with no division under a condition, loops over many
  // directions vectorise.
  const float q = lo / hi;
  float a = hi == 0.f ? 0.f : q;  // a NaN stays NaN
  float s = a * a;
  float p = -0.004355488810688257f;
  p = p * s + 0.023040415719151497f;
  p = p * s - 0.05777395889163017f;
  p = p * s + 0.09794259071350098f;
  p = p * s - 0.1397659033536911f;
  p = p * s + 0.19962705671787262f;
  p = p * s - 0.3333165943622589f;
  float r = a + a * s * p;
  if (ay > ax) r = 1.5707963267948966f - r;
  if (x < 0.f) r = 3.141592653589793f - r;
  return std::copysign(r, y);
}

}  // namespace envgi
