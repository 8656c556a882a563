// Chi-square goodness-of-fit of a direction sampler against its pdf, in the style of
// Mitsuba 3's test suite: histogram samples over the lat-long (u, v) domain, integrate the
// pdf over each cell, pool sparse cells, and return the p-value.
#pragma once

#include <algorithm>
#include <cmath>
#include <functional>
#include <string>
#include <vector>

#include "core/Vec.h"
#include "envmap/EnvironmentMapView.h"

namespace envgi::test {

// Regularised upper incomplete gamma Q(a, x) (series / continued fraction), for chi-square tails.
inline double gammaQ(double a, double x) {
  if (x <= 0.0) return 1.0;
  double gln = std::lgamma(a);
  if (x < a + 1.0) {
    double ap = a, sum = 1.0 / a, del = sum;
    for (int n = 0; n < 100000; ++n) {
      ap += 1.0;
      del *= x / ap;
      sum += del;
      if (std::fabs(del) < std::fabs(sum) * 1e-15) break;
    }
    return 1.0 - sum * std::exp(-x + a * std::log(x) - gln);
  }
  double b = x + 1.0 - a, c = 1.0 / 1e-300, d = 1.0 / b, h = d;
  for (int i = 1; i < 100000; ++i) {
    double an = -i * (i - a);
    b += 2.0;
    d = an * d + b;
    if (std::fabs(d) < 1e-300) d = 1e-300;
    c = b + an / c;
    if (std::fabs(c) < 1e-300) c = 1e-300;
    d = 1.0 / d;
    double del = d * c;
    h *= del;
    if (std::fabs(del - 1.0) < 1e-15) break;
  }
  return std::exp(-x + a * std::log(x) - gln) * h;
}

// Significance for one of `tests` chi-square tests at family-wise level 0.01 (Sidak).
inline double sidakAlpha(int tests, double level = 0.01) { return 1.0 - std::pow(1.0 - level, 1.0 / tests); }

struct ChiSquareResult {
  double pValue = 0.0;
  int dof = 0;
  double chi2 = 0.0;
  double pdfIntegral = 0.0;  // integral of the pdf over the sphere
  std::string message;
};

// sample(i) returns a direction in map-local coordinates; pdf(d) is its solid-angle density.
inline ChiSquareResult chiSquareSphere(const std::function<Vec3f(int)>& sample, const std::function<float(Vec3f)>& pdf,
                                       int sampleCount, int resU = 64, int resV = 32, int sub = 24) {
  std::vector<double> observed(size_t(resU) * resV, 0.0), expected(size_t(resU) * resV, 0.0);
  for (int i = 0; i < sampleCount; ++i) {
    Vec3f d = sample(i);
    if (!(std::fabs(lengthSq(d) - 1.f) < 1e-3f)) continue;  // rejected/invalid samples count as missing
    Vec2f uv = EnvironmentMapView::dirToUV(d);
    int cu = std::clamp(int(uv.x * resU), 0, resU - 1), cv = std::clamp(int(uv.y * resV), 0, resV - 1);
    observed[size_t(cv) * resU + cu] += 1.0;
  }
  // Midpoint rule in (u, v): dOmega = 2 pi^2 sin(pi v) du dv.
  double total = 0.0;
  for (int cv = 0; cv < resV; ++cv)
    for (int cu = 0; cu < resU; ++cu) {
      double acc = 0.0;
      for (int j = 0; j < sub; ++j)
        for (int i = 0; i < sub; ++i) {
          double u = (cu + (i + 0.5) / sub) / resU, v = (cv + (j + 0.5) / sub) / resV;
          Vec3f d = EnvironmentMapView::uvToDir(Vec2f(float(u), float(v)));
          acc += pdf(d) * 2.0 * M_PI * M_PI * std::sin(M_PI * v);
        }
      acc /= double(sub) * sub * resU * resV;
      expected[size_t(cv) * resU + cu] = acc * sampleCount;
      total += acc;
    }
  // Pool cells with expected count < 5 (sorted ascending), as Mitsuba does.
  std::vector<size_t> order(observed.size());
  for (size_t i = 0; i < order.size(); ++i) order[i] = i;
  std::sort(order.begin(), order.end(), [&](size_t a, size_t b) { return expected[a] < expected[b]; });
  ChiSquareResult r;
  r.pdfIntegral = total;
  double pooledObs = 0.0, pooledExp = 0.0;
  int cells = 0;
  for (size_t k : order) {
    if (expected[k] == 0.0) {
      if (observed[k] > 0.0) {
        r.message = "samples fell into a cell of zero pdf";
        r.pValue = 0.0;
        return r;
      }
      continue;
    }
    if (expected[k] < 5.0) {
      pooledObs += observed[k];
      pooledExp += expected[k];
      if (pooledExp >= 5.0) {
        r.chi2 += (pooledObs - pooledExp) * (pooledObs - pooledExp) / pooledExp;
        ++cells;
        pooledObs = pooledExp = 0.0;
      }
      continue;
    }
    r.chi2 += (observed[k] - expected[k]) * (observed[k] - expected[k]) / expected[k];
    ++cells;
  }
  if (pooledExp > 0.0) {
    r.chi2 += (pooledObs - pooledExp) * (pooledObs - pooledExp) / pooledExp;
    ++cells;
  }
  r.dof = std::max(1, cells - 1);
  r.pValue = gammaQ(0.5 * r.dof, 0.5 * r.chi2);
  return r;
}

}  // namespace envgi::test
