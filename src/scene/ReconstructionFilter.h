// Mitsuba 3's pixel reconstruction filters (its `rfilter` plugins): box, tent, gaussian,
// mitchell, catmullrom and lanczos, with their parameters. Each pixel's samples are drawn from
// its filter (filter importance sampling): box, tent and gaussian exactly, with weight one. The
// separable filters with negative lobes are drawn from a table of |f| and carry a weight
// f / (pdf * integral of f), negative in the lobes, whose mean is one; the film then divides
// each pixel by its sum of weights rather than its sample count (FilmSums::weightSum).
#pragma once

#include <cmath>

#include "core/Common.h"
#include "core/Vec.h"
#include "sampling/PiecewiseConstant1D.h"

namespace envgi {

enum class FilterType : int { Box = 0, Tent = 1, Gaussian = 2, Mitchell = 3, CatmullRom = 4, Lanczos = 5 };

// Plain data, copied to the device inside Camera.
struct ReconstructionFilter {
  static constexpr int kBins = 32;  // over [0, radius]; a draw searches these 33 floats
  FilterType type = FilterType::Gaussian;
  float radius = 2.f;   // support's half width in pixels: box 0.5, tent its radius, gaussian 4 sigma
  float stddev = 0.5f;  // gaussian
  float b = 1.f / 3.f, c = 1.f / 3.f;  // Mitchell-Netravali's B and C (Catmull-Rom: 0 and 1/2)
  // Only for the tabulated ones (hasNegativeLobes): the cdf of |f| over bins of [0, radius],
  // and 1 / (the integral of f over [-radius, radius]), which makes the weights' mean one.
  float cdf[kBins + 1] = {};
  float invIntegral = 1.f;

  ENVGI_HD bool hasNegativeLobes() const {
    return type == FilterType::Mitchell || type == FilterType::CatmullRom || type == FilterType::Lanczos;
  }
};

// Where a sample lands relative to the pixel's centre (pixels), and its weight in the film.
struct FilterSample {
  Vec2f offset;
  float weight = 1.f;
};

// The 1D profile of a tabulated filter at x (|x| <= radius), as Mitsuba's plugins define it.
ENVGI_HD inline float filterProfile(const ReconstructionFilter& f, float x) {
  x = std::fabs(x);
  if (x >= f.radius) return 0.f;
  if (f.type == FilterType::Lanczos) {
    if (x < 1e-6f) return 1.f;
    float a = kPi * x, b = a / f.radius;
    return std::sin(a) * std::sin(b) / (a * b);
  }
  // Mitchell and Netravali's cubic (Catmull-Rom is B = 0, C = 1/2).
  const float B = f.b, C = f.c, x2 = x * x, x3 = x2 * x;
  if (x < 1.f) return ((12.f - 9.f * B - 6.f * C) * x3 + (-18.f + 12.f * B + 6.f * C) * x2 + (6.f - 2.f * B)) / 6.f;
  return ((-B - 6.f * C) * x3 + (6.f * B + 30.f * C) * x2 + (-12.f * B - 48.f * C) * x + (8.f * B + 24.f * C)) / 6.f;
}

// One axis of a tabulated filter: u < 1/2 takes the left half, u >= 1/2 the right, each by the
// table's inverse cdf, so x grows with u (and a stratified u stays stratified). Returns x and
// multiplies *w by f(x) / pdf(x).
ENVGI_HD inline float sampleTabulatedAxis(const ReconstructionFilter& f, float u, float* w) {
  const bool left = u < 0.5f;
  float v = left ? 1.f - 2.f * u : 2.f * u - 1.f;
  v = v < 1.f ? v : 1.f - 1e-7f;
  // The last bin with cdf <= v, without branches: which way a random v goes is a coin flip
  // that a branch mispredicts (BM_SampleFilter/3, Mitchell: 81 -> 54 ns a 2D draw).
  const int lo = findIntervalBetweenNoBranch(f.cdf, 0, ReconstructionFilter::kBins - 1, v);
  const float width = f.radius / float(ReconstructionFilter::kBins), mass = f.cdf[lo + 1] - f.cdf[lo];
  float t = mass > 0.f ? (v - f.cdf[lo]) / mass : 0.5f;
  float ax = (float(lo) + fminf(fmaxf(t, 0.f), 1.f)) * width;
  float pdf = 0.5f * mass / width;  // both halves, each half the probability
  *w *= pdf > 0.f ? filterProfile(f, ax) / pdf : 0.f;
  return left ? -ax : ax;
}

// The box's sample: the offset is the draw, centred.
ENVGI_HD inline FilterSample sampleBoxFilter(Vec2f u) {
  FilterSample s;
  s.offset = {u.x - 0.5f, u.y - 0.5f};
  return s;
}

// The offset and weight of a sample drawn from the filter. box, tent and gaussian are drawn
// exactly (weight one); gaussian is not truncated (Mitsuba's is, at 4 sigma: 3e-4 of its mass).
ENVGI_HD inline FilterSample sampleFilter(const ReconstructionFilter& f, Vec2f u) {
  FilterSample s;
  switch (f.type) {
    case FilterType::Box: return sampleBoxFilter(u);
    case FilterType::Tent: {
      auto tent = [](float x) { return x < 0.5f ? std::sqrt(2.f * x) - 1.f : 1.f - std::sqrt(2.f - 2.f * x); };
      s.offset = {f.radius * tent(u.x), f.radius * tent(u.y)};
      return s;
    }
    case FilterType::Gaussian: {
      float r = f.stddev * std::sqrt(-2.f * std::log(fmaxf(1.f - u.x, 1e-12f)));
      float phi = 2.f * kPi * u.y;
      s.offset = {r * std::cos(phi), r * std::sin(phi)};
      return s;
    }
    default: break;
  }
  float w = f.invIntegral * f.invIntegral;  // the 2D filter is f(x) f(y)
  s.offset.x = sampleTabulatedAxis(f, u.x, &w);
  s.offset.y = sampleTabulatedAxis(f, u.y, &w);
  s.weight = w;
  return s;
}

// What a scene's <rfilter> sets; each field is read only by the types that take it, with
// Mitsuba's defaults.
struct FilterParams {
  float radius = 1.f;   // tent
  float stddev = 0.5f;  // gaussian
  float b = 1.f / 3.f, c = 1.f / 3.f;  // mitchell
  int lobes = 3;        // lanczos
};

// A filter of the type with those parameters, its table built for the tabulated ones. Throws
// std::invalid_argument for a parameter out of range (a radius or stddev that is not positive
// and finite, lobes below 1).
ReconstructionFilter makeFilter(FilterType type, const FilterParams& params = {});

}  // namespace envgi
