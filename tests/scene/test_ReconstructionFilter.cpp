// Mitsuba's six pixel filters drawn by importance: the weights' mean is one, the weighted
// samples reproduce the filter's profile (negative lobes included), and a render shows the
// ringing that a filter with negative lobes makes at an edge.
#include <gtest/gtest.h>

#include <algorithm>
#include <vector>

#include "scene/ReconstructionFilter.h"
#include "support/TestScenes.h"

using namespace envgi;

namespace {

struct Case {
  const char* name;
  FilterType type;
  FilterParams params;
};

std::vector<Case> cases() {
  FilterParams tent2, narrow, sharp, four;
  tent2.radius = 2.f;
  narrow.stddev = 0.3f;
  sharp.b = 0.f, sharp.c = 0.75f;
  four.lobes = 4;
  return {{"box", FilterType::Box, {}},           {"tent", FilterType::Tent, {}},
          {"tent r=2", FilterType::Tent, tent2},  {"gaussian", FilterType::Gaussian, {}},
          {"gaussian 0.3", FilterType::Gaussian, narrow}, {"mitchell", FilterType::Mitchell, {}},
          {"mitchell B=0 C=0.75", FilterType::Mitchell, sharp}, {"catmullrom", FilterType::CatmullRom, {}},
          {"lanczos", FilterType::Lanczos, {}},   {"lanczos 4", FilterType::Lanczos, four}};
}

// The filter's 1D profile, however it is defined, normalised or not.
double profile(const ReconstructionFilter& f, double x) {
  x = std::fabs(x);
  switch (f.type) {
    case FilterType::Box: return x < 0.5 ? 1.0 : 0.0;
    case FilterType::Tent: return std::max(0.0, 1.0 - x / f.radius);
    case FilterType::Gaussian: return std::exp(-x * x / (2.0 * f.stddev * f.stddev));
    default: return filterProfile(f, float(x));
  }
}

}  // namespace

// A stratified grid over [0,1)^2: the weighted histogram of x over 40 bins of [-reach, reach]
// (the marginal of f(x) f(y)) against the integral of the profile over each bin, divided by its
// whole integral. A sign lost in a negative lobe, a weight left out or a table searched wrongly
// each move bins by far more than the 2e-3 allowed.
TEST(ReconstructionFilter, WeightedSamplesFollowTheProfile) {
  for (const Case& c : cases()) {
    SCOPED_TRACE(c.name);
    ReconstructionFilter f = makeFilter(c.type, c.params);
    const double reach = c.type == FilterType::Gaussian ? 4.0 * f.stddev : f.radius;
    constexpr int kBins = 40, kN = 1000;
    std::vector<double> hist(kBins, 0.0);
    double meanW = 0.0;
    for (int j = 0; j < kN; ++j)
      for (int i = 0; i < kN; ++i) {
        FilterSample s = sampleFilter(f, Vec2f((i + 0.5f) / kN, (j + 0.5f) / kN));
        ASSERT_TRUE(std::isfinite(s.weight));
        if (c.type != FilterType::Gaussian) {
          ASSERT_LE(std::fabs(s.offset.x), f.radius + 1e-5f);
        }
        meanW += s.weight;
        int b = int((s.offset.x + reach) / (2.0 * reach) * kBins);
        if (b >= 0 && b < kBins) hist[b] += s.weight;
      }
    ASSERT_GT(meanW, 0.0);
    double total = 0.0;
    std::vector<double> ref(kBins, 0.0);
    for (int b = 0; b < kBins; ++b) {
      for (int j = 0; j < 200; ++j) ref[b] += profile(f, -reach + (b + (j + 0.5) / 200.0) * 2.0 * reach / kBins);
      total += ref[b];
    }
    bool negative = false;
    for (int b = 0; b < kBins; ++b) {
      EXPECT_NEAR(hist[b] / meanW, ref[b] / total, 2e-3) << "bin " << b;
      negative |= ref[b] < 0.0;
    }
    EXPECT_EQ(negative, f.hasNegativeLobes());  // the table's filters are the ones with negative lobes
  }
}

// The weights average one, so the film divides by the sample count alone; a filter whose
// integral is off (1 / invIntegral) shows here. The points form a Latin hypercube of 2^20:
// each axis stratified alone, since a table's weight jumps at its bins' edges and a square
// grid's error then falls only as 1/N an axis.
TEST(ReconstructionFilter, WeightsAverageOne) {
  for (const Case& c : cases()) {
    SCOPED_TRACE(c.name);
    ReconstructionFilter f = makeFilter(c.type, c.params);
    constexpr uint32_t kN = 1u << 20;
    double sum = 0.0, minW = 1e30;
    for (uint32_t i = 0; i < kN; ++i) {
      uint32_t j = (i * 2654435761u) & (kN - 1);  // an odd multiplier permutes [0, 2^20)
      FilterSample s = sampleFilter(f, Vec2f((float(i) + 0.5f) / float(kN), (float(j) + 0.5f) / float(kN)));
      sum += s.weight;
      minW = std::min(minW, double(s.weight));
    }
    EXPECT_NEAR(sum / double(kN), 1.0, 2e-3);
    // Only the filters with negative lobes draw negative weights, and they do draw them.
    if (f.hasNegativeLobes()) EXPECT_LT(minW, 0.0);
    else EXPECT_EQ(minW, 1.0);
  }
}

// The profiles at points where Mitsuba's definitions give round numbers.
TEST(ReconstructionFilter, ProfilesMatchTheirDefinitions) {
  ReconstructionFilter m = makeFilter(FilterType::Mitchell);
  EXPECT_NEAR(filterProfile(m, 0.f), (6.f - 2.f / 3.f) / 6.f, 1e-6f);
  EXPECT_NEAR(filterProfile(m, 1.f), (1.f / 3.f) / 6.f, 1e-6f);  // B / 6 where the pieces meet
  EXPECT_EQ(filterProfile(m, 2.f), 0.f);
  EXPECT_NEAR(1.f / m.invIntegral, 1.f, 1e-5f);  // the cubics integrate to one for any B, C
  ReconstructionFilter cr = makeFilter(FilterType::CatmullRom);
  EXPECT_NEAR(filterProfile(cr, 0.f), 1.f, 1e-6f);
  EXPECT_NEAR(filterProfile(cr, 1.f), 0.f, 1e-6f);  // interpolating: zero at the neighbours
  EXPECT_LT(filterProfile(cr, 1.5f), 0.f);
  ReconstructionFilter l = makeFilter(FilterType::Lanczos);
  EXPECT_EQ(l.radius, 3.f);
  EXPECT_NEAR(filterProfile(l, 0.f), 1.f, 1e-6f);
  EXPECT_NEAR(filterProfile(l, 1.f), 0.f, 1e-6f);
  EXPECT_NEAR(filterProfile(l, 2.f), 0.f, 1e-6f);
  EXPECT_LT(filterProfile(l, 1.5f), 0.f);
  EXPECT_EQ(makeFilter(FilterType::Gaussian).radius, 2.f);
  EXPECT_EQ(makeFilter(FilterType::Box).radius, 0.5f);
}

TEST(ReconstructionFilter, ParametersOutOfRangeAreErrors) {
  FilterParams p;
  p.radius = 0.f;
  EXPECT_THROW(makeFilter(FilterType::Tent, p), std::invalid_argument);
  p.radius = NAN;
  EXPECT_THROW(makeFilter(FilterType::Tent, p), std::invalid_argument);
  p = {};
  p.stddev = -0.5f;
  EXPECT_THROW(makeFilter(FilterType::Gaussian, p), std::invalid_argument);
  p = {};
  p.lobes = 0;
  EXPECT_THROW(makeFilter(FilterType::Lanczos, p), std::invalid_argument);
  p = {};
  p.b = INFINITY;
  EXPECT_THROW(makeFilter(FilterType::Mitchell, p), std::invalid_argument);
  p = {};
  p.radius = 0.f;  // read by tent only
  EXPECT_NO_THROW(makeFilter(FilterType::Box, p));
}

// A black sphere against a white sky (radiance 1): with a box filter every pixel lies in
// [0, 1]; with Lanczos the pixels beside the silhouette overshoot on both sides, as a filter
// with negative lobes does (Mitsuba's images show the same), while the sky far from the
// sphere stays at one exactly: the film divides by the weights' sum, so where every sample
// sees the same radiance the signed weights cancel (divided by the sample count, the 6x6
// corner's pixels spread by 0.2 at 64 spp).
TEST(ReconstructionFilter, NegativeLobesRingAtAnEdge) {
  Bsdf black;
  black.reflectance = Color(0.f);
  auto extremes = [&](FilterType t, float* lo, float* hi, float* corner, IntegratorType integrator = IntegratorType::Path) {
    auto s = test::furnaceScene(black, 48, 64);
    s->camera.filter = makeFilter(t);
    s->integrator.type = integrator;
    s->integrator.sppm.photonCount = 2000;
    s->finalize();  // the view copies the camera
    EmbreeAccel accel(*s);
    RenderOptions o;
    o.progress = false;
    RenderStats st;
    Image img = render(*s, accel, o, &st);
    EXPECT_EQ(st.nonFiniteSamples, 0u);
    *lo = 1e30f, *hi = -1e30f;
    for (int y = 0; y < 48; ++y)
      for (int x = 0; x < 48; ++x) {
        float v = img.at(x, y).y;
        *lo = std::min(*lo, v), *hi = std::max(*hi, v);
      }
    *corner = 1.f;  // the pixel furthest from one among the 6x6 in the corner, 10 pixels from the sphere
    for (int y = 0; y < 6; ++y)
      for (int x = 0; x < 6; ++x)
        if (std::fabs(img.at(x, y).y - 1.f) > std::fabs(*corner - 1.f)) *corner = img.at(x, y).y;
  };
  float lo, hi, corner;
  extremes(FilterType::Box, &lo, &hi, &corner);
  EXPECT_GE(lo, 0.f);
  EXPECT_LE(hi, 1.f + 1e-5f);
  extremes(FilterType::Lanczos, &lo, &hi, &corner);
  EXPECT_LT(lo, -0.02f);
  EXPECT_GT(hi, 1.02f);
  EXPECT_NEAR(corner, 1.f, 1e-5f);
  // SPPM's film divides by the weights' sum too (64 passes, one camera sample a pixel each).
  extremes(FilterType::Lanczos, &lo, &hi, &corner, IntegratorType::Sppm);
  EXPECT_LT(lo, -0.02f);
  EXPECT_GT(hi, 1.02f);
  EXPECT_NEAR(corner, 1.f, 1e-5f);
}
