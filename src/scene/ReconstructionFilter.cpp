#include "scene/ReconstructionFilter.h"

#include <fmt/format.h>

#include <stdexcept>

namespace envgi {

ReconstructionFilter makeFilter(FilterType type, const FilterParams& params) {
  ReconstructionFilter f;
  f.type = type;
  auto positive = [](float v, const char* what) {
    if (!(v > 0.f && v < 1e6f)) throw std::invalid_argument(fmt::format("{} must be positive, got {}", what, v));
    return v;
  };
  switch (type) {
    case FilterType::Box: f.radius = 0.5f; return f;
    case FilterType::Tent: f.radius = positive(params.radius, "tent's radius"); return f;
    case FilterType::Gaussian:
      f.stddev = positive(params.stddev, "gaussian's stddev");
      f.radius = 4.f * f.stddev;
      return f;
    case FilterType::Mitchell:
      if (!std::isfinite(params.b) || !std::isfinite(params.c)) throw std::invalid_argument("mitchell's B and C must be finite");
      f.b = params.b, f.c = params.c, f.radius = 2.f;
      break;
    case FilterType::CatmullRom: f.b = 0.f, f.c = 0.5f, f.radius = 2.f; break;
    case FilterType::Lanczos:
      if (params.lobes < 1 || params.lobes > 64)
        throw std::invalid_argument(fmt::format("lanczos's lobes must be 1 to 64, got {}", params.lobes));
      f.radius = float(params.lobes);
      break;
  }
  // |f| and f over each bin of [0, radius], by the midpoint rule on 64 points a bin: the table
  // need only be close to |f|, since each sample's weight uses f itself; the integral of f sets
  // the weights' mean, and 2048 points over a smooth profile give it to about 1e-6.
  constexpr int kSub = 64;
  const int n = ReconstructionFilter::kBins;
  const double width = double(f.radius) / n;
  double absSum = 0.0, sum = 0.0;
  double acc[ReconstructionFilter::kBins + 1] = {0.0};
  for (int i = 0; i < n; ++i) {
    double a = 0.0;
    for (int j = 0; j < kSub; ++j) {
      double v = filterProfile(f, float((i + (j + 0.5) / kSub) * width));
      a += std::fabs(v) * width / kSub;
      sum += v * width / kSub;
    }
    absSum += a;
    acc[i + 1] = absSum;
  }
  if (!(sum > 0.0)) throw std::invalid_argument("the filter's integral is not positive (mitchell's B and C?)");
  for (int i = 1; i <= n; ++i) f.cdf[i] = float(acc[i] / absSum);
  f.cdf[n] = 1.f;
  f.invIntegral = float(1.0 / (2.0 * sum));
  return f;
}

}  // namespace envgi
