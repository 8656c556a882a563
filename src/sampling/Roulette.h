// Russian roulette (Arvo and Kirk 1990), the one copy every path and photon tracer uses.
#pragma once

#include "core/Vec.h"

namespace envgi {

// Camera paths survive with at most this probability, so a path of bright throughput still
// ends eventually.
inline constexpr float kRouletteMaxSurvival = 0.95f;

// A path carrying `weight` goes on with probability q = min(max component * scale, qMax), and
// its weight is divided by q so the estimate stays unbiased. False: the path ends. scale
// undoes what is not lost energy (the eta^2 of refraction), so paths inside glass are not
// killed and then boosted into fireflies.
ENVGI_INLINE bool russianRoulette(Color* weight, float u, float qMax, float scale = 1.f) {
  float q = fminf(maxComponent(*weight) * scale, qMax);
  if (!(q > 0.f) || u >= q) return false;
  *weight = *weight / q;
  return true;
}

}  // namespace envgi
