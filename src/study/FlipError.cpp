#include "study/FlipError.h"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

namespace envgi {

namespace {

constexpr float kPi = 3.14159265358979f;
// The paper's constants: the colour difference's exponent qc, the cut-off pc and its share pt
// of the range, the feature filter's width (degrees) and the feature difference's exponent qf.
constexpr float kQc = 0.7f, kPc = 0.4f, kPt = 0.95f, kGw = 0.082f, kQf = 0.5f;
// The contrast sensitivity filters, a sum of two Gaussians a sqrt(pi / b) exp(-pi^2 x^2 / b) a
// channel (x in degrees): achromatic, red-green, blue-yellow.
constexpr float kA1[3] = {1.f, 1.f, 34.1f}, kB1[3] = {0.0047f, 0.0053f, 0.04f};
constexpr float kA2[3] = {0.f, 0.f, 13.5f}, kB2[3] = {1e-5f, 1e-5f, 0.025f};
// D65 white, for CIELAB and YCxCz.
constexpr float kWhite[3] = {0.950428545f, 1.f, 1.088900371f};

struct Rgb {
  float x = 0.f, y = 0.f, z = 0.f;
};

Rgb linearToXyz(Rgb c) {
  return {0.412390799f * c.x + 0.357584339f * c.y + 0.180480788f * c.z,
          0.212639006f * c.x + 0.715168679f * c.y + 0.072192315f * c.z,
          0.019330819f * c.x + 0.119194780f * c.y + 0.950532152f * c.z};
}
Rgb xyzToLinear(Rgb c) {
  return {3.241003275f * c.x - 1.537398934f * c.y - 0.498615861f * c.z,
          -0.969224334f * c.x + 1.875930071f * c.y + 0.041554224f * c.z,
          0.055639423f * c.x - 0.204011202f * c.y + 1.057148933f * c.z};
}
// YCxCz: CIELAB without its cube root, linear in XYZ, so that filtering commutes with it.
Rgb xyzToYcxcz(Rgb c) {
  const float x = c.x / kWhite[0], y = c.y, z = c.z / kWhite[2];
  return {116.f * y - 16.f, 500.f * (x - y), 200.f * (y - z)};
}
Rgb ycxczToXyz(Rgb c) {
  const float y = (c.x + 16.f) / 116.f;
  return {(y + c.y / 500.f) * kWhite[0], y, (y - c.z / 200.f) * kWhite[2]};
}
float labCurve(float t) {
  const float d = 6.f / 29.f;
  return t > d * d * d ? std::cbrt(t) : t / (3.f * d * d) + 4.f / 29.f;
}
// CIELAB with the Hunt adjustment: chroma scaled by lightness (0.01 L).
Rgb huntLab(Rgb linear) {
  const Rgb c = linearToXyz(linear);
  const float fx = labCurve(c.x / kWhite[0]), fy = labCurve(c.y), fz = labCurve(c.z / kWhite[2]);
  const float L = 116.f * fy - 16.f;
  return {L, 0.01f * L * 500.f * (fx - fy), 0.01f * L * 200.f * (fy - fz)};
}
// HyAB: city-block distance in lightness, Euclidean in chroma.
float hyab(Rgb a, Rgb b) { return std::fabs(a.x - b.x) + std::hypot(a.y - b.y, a.z - b.z); }

// One 1D filter's taps, for separable convolution with clamp-to-edge.
struct Taps {
  int radius = 0;
  std::vector<float> w;
  float operator[](int i) const { return w[size_t(i + radius)]; }
};

// The contrast sensitivity filters: Y and Cx one Gaussian each, Cz a sum of two, which is
// separated as the sum of two separable filters of square-root amplitude.
struct SpatialFilters {
  Taps y, cx, cz1, cz2;
};
SpatialFilters spatialFilters(float ppd) {
  const float maxB = std::max({kB1[0], kB1[1], kB1[2], kB2[0], kB2[1], kB2[2]});
  const int r = int(std::ceil(3.f * std::sqrt(maxB / (2.f * kPi * kPi)) * ppd));
  SpatialFilters f;
  for (Taps* t : {&f.y, &f.cx, &f.cz1, &f.cz2}) t->radius = r, t->w.resize(size_t(2 * r + 1));
  auto gaussian = [](float x2, float a, float b) { return a * std::sqrt(kPi / b) * std::exp(-kPi * kPi * x2 / b); };
  auto gaussianSqrt = [](float x2, float a, float b) {
    return std::sqrt(a * std::sqrt(kPi / b)) * std::exp(-kPi * kPi * x2 / b);
  };
  float sy = 0.f, scx = 0.f, s1 = 0.f, s2 = 0.f;
  for (int i = -r; i <= r; ++i) {
    const float x = float(i) / ppd, x2 = x * x;
    const size_t k = size_t(i + r);
    sy += f.y.w[k] = gaussian(x2, kA1[0], kB1[0]);
    scx += f.cx.w[k] = gaussian(x2, kA1[1], kB1[1]);
    s1 += f.cz1.w[k] = gaussianSqrt(x2, kA1[2], kB1[2]);
    s2 += f.cz2.w[k] = gaussianSqrt(x2, kA2[2], kB2[2]);
  }
  const float nz = 1.f / std::sqrt(s1 * s1 + s2 * s2);
  for (size_t k = 0; k < f.y.w.size(); ++k) f.y.w[k] /= sy, f.cx.w[k] /= scx, f.cz1.w[k] *= nz, f.cz2.w[k] *= nz;
  return f;
}

// The feature filters: a Gaussian of sigma 0.5 w (degrees) and its first and second
// derivatives, each derivative's positive and negative taps normalised to 1 and -1.
struct FeatureFilters {
  Taps g, dg, ddg;
};
FeatureFilters featureFilters(float ppd) {
  const float sigma = 0.5f * kGw * ppd;
  const int r = int(std::ceil(3.f * sigma));
  FeatureFilters f;
  for (Taps* t : {&f.g, &f.dg, &f.ddg}) t->radius = r, t->w.resize(size_t(2 * r + 1));
  float sg = 0.f, dPos = 0.f, dNeg = 0.f, ddPos = 0.f, ddNeg = 0.f;
  for (int i = -r; i <= r; ++i) {
    const float x = float(i), g = std::exp(-(x * x) / (2.f * sigma * sigma));
    const float dg = -x * g, ddg = (x * x / (sigma * sigma) - 1.f) * g;
    const size_t k = size_t(i + r);
    f.g.w[k] = g, f.dg.w[k] = dg, f.ddg.w[k] = ddg;
    sg += g;
    (dg > 0.f ? dPos : dNeg) += std::fabs(dg);
    (ddg > 0.f ? ddPos : ddNeg) += std::fabs(ddg);
  }
  for (size_t k = 0; k < f.g.w.size(); ++k) {
    f.g.w[k] /= sg;
    f.dg.w[k] /= f.dg.w[k] > 0.f ? dPos : dNeg;
    f.ddg.w[k] /= f.ddg.w[k] > 0.f ? ddPos : ddNeg;
  }
  return f;
}

// A plane of floats, read with clamp-to-edge.
struct Plane {
  int w = 0, h = 0;
  std::vector<float> v;
  Plane(int width, int height) : w(width), h(height), v(size_t(width) * size_t(height), 0.f) {}
  float at(int x, int y) const { return v[size_t(std::clamp(y, 0, h - 1)) * size_t(w) + size_t(std::clamp(x, 0, w - 1))]; }
  float& operator()(int x, int y) { return v[size_t(y) * size_t(w) + size_t(x)]; }
};

template <class F>
void forRows(int h, F f) {
  tbb::parallel_for(0, h, [&](int y) { f(y); });
}

float horizontal(const Plane& p, const Taps& t, int x, int y) {
  float s = 0.f;
  for (int i = -t.radius; i <= t.radius; ++i) s += t[i] * p.at(x + i, y);
  return s;
}
float vertical(const Plane& p, const Taps& t, int x, int y) {
  float s = 0.f;
  for (int i = -t.radius; i <= t.radius; ++i) s += t[i] * p.at(x, y + i);
  return s;
}

// One image in YCxCz, a plane a channel.
struct Opponent {
  Plane y, cx, cz;
  explicit Opponent(const Image& linear) : y(linear.width, linear.height), cx(y), cz(y) {
    for (int j = 0; j < y.h; ++j)
      for (int i = 0; i < y.w; ++i) {
        const float* p = &linear.rgb[3 * (size_t(j) * size_t(linear.width) + size_t(i))];
        const Rgb c = xyzToYcxcz(linearToXyz({std::clamp(p[0], 0.f, 1.f), std::clamp(p[1], 0.f, 1.f),
                                              std::clamp(p[2], 0.f, 1.f)}));
        y(i, j) = c.x, cx(i, j) = c.y, cz(i, j) = c.z;
      }
  }
};

// The filtered image, in CIELAB with the Hunt adjustment, a pixel at a time.
std::vector<Rgb> filteredLab(const Opponent& o, const SpatialFilters& f) {
  const int w = o.y.w, h = o.y.h;
  Plane y(w, h), cx(w, h), cz1(w, h), cz2(w, h);
  forRows(h, [&](int j) {
    for (int i = 0; i < w; ++i) {
      y(i, j) = horizontal(o.y, f.y, i, j), cx(i, j) = horizontal(o.cx, f.cx, i, j);
      cz1(i, j) = horizontal(o.cz, f.cz1, i, j), cz2(i, j) = horizontal(o.cz, f.cz2, i, j);
    }
  });
  std::vector<Rgb> out(size_t(w) * size_t(h));
  forRows(h, [&](int j) {
    for (int i = 0; i < w; ++i) {
      const Rgb c{vertical(y, f.y, i, j), vertical(cx, f.cx, i, j),
                  vertical(cz1, f.cz1, i, j) + vertical(cz2, f.cz2, i, j)};
      Rgb lin = xyzToLinear(ycxczToXyz(c));
      lin = {std::clamp(lin.x, 0.f, 1.f), std::clamp(lin.y, 0.f, 1.f), std::clamp(lin.z, 0.f, 1.f)};
      out[size_t(j) * size_t(w) + size_t(i)] = huntLab(lin);
    }
  });
  return out;
}

// Edge and point strengths of the achromatic channel (Y scaled to [0, 1]), a pixel at a time.
struct Features {
  std::vector<float> edge, point;
};
Features features(const Plane& yc, const FeatureFilters& f) {
  const int w = yc.w, h = yc.h;
  Plane gray(w, h);
  for (size_t k = 0; k < gray.v.size(); ++k) gray.v[k] = yc.v[k] * (1.f / 116.f) + 16.f / 116.f;
  Plane dx(w, h), ddx(w, h), gs(w, h);
  forRows(h, [&](int j) {
    for (int i = 0; i < w; ++i)
      dx(i, j) = horizontal(gray, f.dg, i, j), ddx(i, j) = horizontal(gray, f.ddg, i, j),
            gs(i, j) = horizontal(gray, f.g, i, j);
  });
  Features out{std::vector<float>(gray.v.size()), std::vector<float>(gray.v.size())};
  forRows(h, [&](int j) {
    for (int i = 0; i < w; ++i) {
      const float ex = vertical(dx, f.g, i, j), ey = vertical(gs, f.dg, i, j);
      const float px = vertical(ddx, f.g, i, j), py = vertical(gs, f.ddg, i, j);
      const size_t k = size_t(j) * size_t(w) + size_t(i);
      out.edge[k] = std::sqrt(ex * ex + ey * ey), out.point[k] = std::sqrt(px * px + py * py);
    }
  });
  return out;
}

void requireSameSize(const Image& ref, const Image& test) {
  if (ref.width != test.width || ref.height != test.height)
    throw std::runtime_error("FLIP: the reference is " + std::to_string(ref.width) + "x" +
                             std::to_string(ref.height) + ", the image " + std::to_string(test.width) + "x" +
                             std::to_string(test.height));
}

// ACES's curve as FLIP fits it (Narkowicz's, with 0.6 of pre-exposure taken out): per channel
// (a c^2 + b c + e) / (d c^2 + f c + g).
constexpr float kAces[6] = {0.6f * 0.6f * 2.51f, 0.6f * 0.03f, 0.f, 0.6f * 0.6f * 2.43f, 0.6f * 0.59f, 0.14f};
float aces(float c) { return (c * c * kAces[0] + c * kAces[1] + kAces[2]) / (c * c * kAces[3] + c * kAces[4] + kAces[5]); }

}  // namespace

std::vector<float> flipLdr(const Image& ref, const Image& test, float ppd) {
  requireSameSize(ref, test);
  if (!(ppd > 0.f)) throw std::runtime_error("FLIP: pixels per degree must be positive");
  const Opponent r(ref), t(test);
  const SpatialFilters sf = spatialFilters(ppd);
  const std::vector<Rgb> labR = filteredLab(r, sf), labT = filteredLab(t, sf);
  const FeatureFilters ff = featureFilters(ppd);
  const Features fr = features(r.y, ff), ft = features(t.y, ff);
  const float cmax = std::pow(hyab(huntLab({0.f, 1.f, 0.f}), huntLab({0.f, 0.f, 1.f})), kQc), pccmax = kPc * cmax;
  std::vector<float> out(labR.size());
  for (size_t k = 0; k < out.size(); ++k) {
    // The colour difference, its first pc of the range stretched over pt of [0, 1].
    float dc = std::pow(hyab(labR[k], labT[k]), kQc);
    dc = dc < pccmax ? dc * kPt / pccmax : kPt + (dc - pccmax) / (cmax - pccmax) * (1.f - kPt);
    const float df = std::pow(
        std::max(std::fabs(fr.edge[k] - ft.edge[k]), std::fabs(fr.point[k] - ft.point[k])) / std::sqrt(2.f), kQf);
    out[k] = std::pow(dc, 1.f - df);
  }
  return out;
}

FlipExposures flipExposures(const Image& ref) {
  // The exposure at which ACES reaches 0.85 for the brightest pixel starts the range, and the
  // one at which the median pixel does ends it: a x^2 + b x + c = 0 for 0.85 of the curve.
  const float t = 0.85f, a = kAces[0] - t * kAces[3], b = kAces[1] - t * kAces[4], c = kAces[2] - t * kAces[5];
  const float d1 = -0.5f * (b / a), xMax = d1 + std::sqrt(d1 * d1 - c / a);
  std::vector<float> lum(size_t(ref.width) * size_t(ref.height));
  float yMax = 0.f;
  for (size_t k = 0; k < lum.size(); ++k) {
    const float* p = &ref.rgb[3 * k];
    lum[k] = 0.2126f * p[0] + 0.7152f * p[1] + 0.0722f * p[2];
    yMax = std::max(yMax, lum[k]);
  }
  FlipExposures e;
  if (lum.empty() || !(yMax > 0.f) || !std::isfinite(yMax)) return e;  // black: no exposure shows anything
  std::nth_element(lum.begin(), lum.begin() + std::ptrdiff_t(lum.size() / 2), lum.end());
  float yMedian = lum[lum.size() / 2];
  if (!(yMedian > 0.f)) yMedian = yMax;  // mostly black: one exposure's worth
  e.start = std::log2(xMax / yMax);
  e.stop = std::log2(xMax / yMedian);
  e.count = int(std::max(2.f, std::ceil(e.stop - e.start)));
  return e;
}

std::vector<float> flipHdr(const Image& ref, const Image& test, float ppd) {
  requireSameSize(ref, test);
  const FlipExposures e = flipExposures(ref);
  std::vector<float> out(size_t(ref.width) * size_t(ref.height), 0.f);
  if (e.count == 0) return flipLdr(ref, test, ppd);
  const float step = (e.stop - e.start) / float(e.count - 1);
  Image r = ref, t = test;
  for (int i = 0; i < e.count; ++i) {
    const float m = std::pow(2.f, e.start + float(i) * step);
    for (size_t k = 0; k < r.rgb.size(); ++k) r.rgb[k] = aces(ref.rgb[k] * m), t.rgb[k] = aces(test.rgb[k] * m);
    const std::vector<float> ldr = flipLdr(r, t, ppd);
    for (size_t k = 0; k < out.size(); ++k) out[k] = std::max(out[k], ldr[k]);
  }
  return out;
}

double flipMean(const std::vector<float>& map) {
  double s = 0.0;
  for (float v : map) s += double(v);
  return map.empty() ? 0.0 : s / double(map.size());
}

}  // namespace envgi
