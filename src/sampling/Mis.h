// Multiple importance sampling weights (the paper's Eq. 3 to 6 and Veach's power heuristic).
#pragma once

#include "core/Common.h"

namespace envgi {

// Two strategies: weight of the one that drew the sample (nf samples with density fPdf).
ENVGI_INLINE float balanceHeuristic(float nf, float fPdf, float ng, float gPdf) {
  float f = nf * fPdf, g = ng * gPdf;
  return f + g > 0.f ? f / (f + g) : 0.f;
}
ENVGI_INLINE float powerHeuristic(float nf, float fPdf, float ng, float gPdf) {
  float f = nf * fPdf, g = ng * gPdf;
  if (std::isinf(f * f)) return 1.f;
  return f * f + g * g > 0.f ? (f * f) / (f * f + g * g) : 0.f;
}

// Which of the two an estimator combines its light and BSDF samples with: the balance heuristic
// is the paper's Eq. 5-6; the power heuristic (beta = 2) is Veach's usual choice.
enum class MisHeuristic : int { Power = 0, Balance = 1 };
ENVGI_INLINE float misHeuristic(MisHeuristic h, float nf, float fPdf, float ng, float gPdf) {
  return h == MisHeuristic::Balance ? balanceHeuristic(nf, fPdf, ng, gPdf) : powerHeuristic(nf, fPdf, ng, gPdf);
}

// Any number of strategies: w_i = (c_i p_i)^beta / sum_k (c_k p_k)^beta. beta = 1 is the
// balance heuristic of Eq. 5-6 (c_i = n_i / n), beta = 2 the power heuristic.
ENVGI_INLINE float misWeight(int i, const float* counts, const float* pdfs, int k, float beta) {
  float denom = 0.f, num = 0.f;
  for (int j = 0; j < k; ++j) {
    float t = counts[j] * pdfs[j];
    float tb = beta == 1.f ? t : (beta == 2.f ? t * t : std::pow(t, beta));
    denom += tb;
    if (j == i) num = tb;
  }
  return denom > 0.f ? num / denom : 0.f;
}

}  // namespace envgi
