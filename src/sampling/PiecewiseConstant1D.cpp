#include "sampling/PiecewiseConstant1D.h"

#include <stdexcept>

namespace envgi {

void PiecewiseConstant1D::build(const float* f, int n, float* funcOut, float* cdfOut, float* intOut) {
  if (n <= 0) throw std::invalid_argument("PiecewiseConstant1D: empty function");
  // Accumulate in double: a 4096-wide row of tiny values next to a sun loses bits in float.
  double sum = 0.0;
  cdfOut[0] = 0.f;
  std::vector<double> acc(n + 1, 0.0);
  for (int i = 0; i < n; ++i) {
    float v = f[i];
    if (!(v >= 0.f) || !std::isfinite(v)) v = 0.f;
    funcOut[i] = v;
    sum += double(v) / n;
    acc[i + 1] = sum;
  }
  *intOut = float(sum);
  if (sum <= 0.0) {
    for (int i = 1; i <= n; ++i) cdfOut[i] = float(i) / float(n);
  } else {
    for (int i = 1; i <= n; ++i) cdfOut[i] = float(acc[i] / sum);
  }
  cdfOut[n] = 1.f;
}

void buildGuide(const float* cdf, int size, int G, int* guide) {
  if (G <= 0 || (G & (G - 1)) != 0) throw std::invalid_argument("buildGuide: the guide size must be a power of two");
  for (int g = 0; g <= G; ++g) guide[g] = findInterval(cdf, size, float(g) / float(G));
}

int guideSize(int n, int perEntry) {
  int G = 1;
  while (G * perEntry < n) G *= 2;
  return G;
}

}  // namespace envgi
