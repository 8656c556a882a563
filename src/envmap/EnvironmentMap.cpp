#include "envmap/EnvironmentMap.h"
#include "envmap/LightProbe.h"

#include <spdlog/spdlog.h>

#include <algorithm>
#include <numeric>
#include <stdexcept>

namespace envgi {

namespace {

// One bit a pixel: whether draws inside it follow the bilinear lookup (warpInPixel). Only where
// the lookup varies by more than 2x over the pixel, judged by its 3 x 3 neighbourhood (which is
// what the lookup there is made of): elsewhere the uniform point's L / p stays within 2x of its
// mean, and the warp, which reads those nine texels on every draw and every pdf, would cost
// more time than it saves variance. 8.5% of Grace Cathedral's pixels qualify, 29% of the sunrise map's.
std::vector<uint32_t> pixelsToWarp(const EnvironmentMapView& v) {
  std::vector<uint32_t> bits((size_t(v.width) * v.height + 31) / 32, 0u);
  for (int y = 0; y < v.height; ++y)
    for (int x = 0; x < v.width; ++x) {
      float l[3][3], lo = INFINITY, hi = 0.f;
      v.neighbourhoodLuminance(x, y, l);
      for (const auto& row : l)
        for (float e : row) lo = std::min(lo, e), hi = std::max(hi, e);
      size_t i = size_t(y) * v.width + x;
      // Nor below 1e-15 or above 1e15: the warp squares lattice values (sampleLinear) and takes
      // ratios of their sums, which lose their digits to underflow near FLT_MIN (a draw's density
      // differed from pdf()'s by 1.6% on a map of 1e-43 texels: fuzz_envmap) and overflow to
      // infinity past 1.8e19 (by 3.7x next to texels of 1e30). Such a pixel is drawn
      // uniformly inside, as a flat one is; a measured sun (about 1.6e9) stays well inside.
      if (hi > 2.f * lo && hi >= 1e-15f && hi <= 1e15f) bits[i >> 5] |= 1u << (i & 31);
    }
  return bits;
}

float rowSinTheta(int y, int height) { return std::sin(kPi * (float(y) + 0.5f) / float(height)); }

// Exact solid angle of one pixel of row y: (2 pi / width) (cos theta0 - cos theta1).
double pixelSolidAngle(int y, int width, int height) {
  return (2.0 * M_PI / width) * (std::cos(M_PI * y / height) - std::cos(M_PI * (y + 1) / height));
}

}  // namespace

EnvironmentMap EnvironmentMap::load(const std::string& path, const EnvironmentMapOptions& opts) {
  Image img = loadImage(path);
  if (img.width < 2 || img.height < 1)
    throw std::runtime_error("environment map '" + path + "' is too small (" + std::to_string(img.width) + "x" +
                             std::to_string(img.height) + ")");
  if (img.width != 2 * img.height)
    spdlog::warn("environment map '{}' is {}x{}, not 2:1; it is still read as lat-long{}", path, img.width, img.height,
                 img.width == img.height ? " (a light probe? the envmap's 'layout' reads angular maps, mirror balls and cube crosses)" : "");
  if (!opts.bilinear) return EnvironmentMap(std::move(img), opts, path);
  // Invalid texels are zeroed before the rows are blended, so that each counts once and
  // spreads nothing into its neighbours.
  size_t invalid = zeroInvalidRadiance(img);
  if (invalid > 0)
    spdlog::warn("environment map '{}': {} NaN, infinite or negative channel values replaced with 0", path, invalid);
  // The density follows the rows resampled to pixel centres; the lookup reads the file's own
  // rows on Mitsuba's grid. Sampling stays unbiased (its pdf comes from the same tables), and
  // the density follows the lookup to within a second linear interpolation.
  EnvironmentMap map(rowsAtPixelCentres(img), opts, path);
  map.invalid_ = invalid;
  if (img.height >= 2) {  // the lookup's r, g, b become the file's own rows
    map.setLookupRgb(img);
    map.rowsFromPoles_ = true;
    map.buildAlgorithm1Table();
  }
  return map;
}

void EnvironmentMap::buildAlgorithm1Table() {
  // Algorithm 1: the pixel's luminance times sin(theta) at its row's centre (the paper's
  // cos(phi) of the latitude). Under MIS compensation, max(Y - mean, 0) in place of Y.
  const int w = width_, h = height_;
  std::vector<float> lum(size_t(w) * h);
  for (size_t i = 0; i < lum.size(); ++i) lum[i] = luminance(texels_[i * 4], texels_[i * 4 + 1], texels_[i * 4 + 2]);
  if (opts_.misCompensation) {
    double sum = 0.0, sa = 0.0;
    for (int y = 0; y < h; ++y)
      for (int x = 0; x < w; ++x) sum += lum[size_t(y) * w + x] * rowSinTheta(y, h), sa += rowSinTheta(y, h);
    const float mean = sa > 0.0 ? float(sum / sa) : 0.f;
    bool any = false;
    for (float& l : lum) any = any || l > mean;
    if (any)
      for (float& l : lum) l = std::max(l - mean, 0.f);
  }
  std::vector<float> weight(lum.size());
  double total = 0.0;
  int positive = 0;
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      weight[size_t(y) * w + x] = lum[size_t(y) * w + x] * rowSinTheta(y, h);
      total += weight[size_t(y) * w + x];
      positive += weight[size_t(y) * w + x] > 0.f;
    }
  // A black pixel beside a lit one still shows light through the bilinear lookup: it keeps a
  // floor of 1e-4 of the mean weight, so the density is positive wherever the lookup is and the
  // estimator stays unbiased (Algorithm 1 itself would give it none).
  if (opts_.bilinear && positive > 0 && !opts_.misCompensation) {
    const float floorWeight = float(1e-4 * total / positive);
    std::vector<float> out = weight;
    for (int y = 0; y < h; ++y)
      for (int x = 0; x < w; ++x) {
        if (weight[size_t(y) * w + x] > 0.f) continue;
        bool litNeighbour = false;
        for (int dy = -1; dy <= 1; ++dy)
          for (int dx = -1; dx <= 1; ++dx) {
            const int yy = std::clamp(y + dy, 0, h - 1), xx = (x + dx + w) % w;
            litNeighbour = litNeighbour || lum[size_t(yy) * w + xx] > 0.f;
          }
        if (litNeighbour) out[size_t(y) * w + x] = floorWeight * rowSinTheta(y, h);
      }
    weight.swap(out);
  }
  paperDist_ = PiecewiseConstant2D(weight.data(), w, h);
}

void EnvironmentMap::setLookupRgb(const Image& img) {
  for (size_t i = 0; i < size_t(width_) * height_; ++i)
    for (int k = 0; k < 3; ++k) texels_[i * 4 + k] = img.rgb[i * 3 + k];
}

Image EnvironmentMap::rowsAtPixelCentres(const Image& src) {
  const int w = src.width, h = src.height;
  if (h < 2) return src;
  Image out(w, h);
  // Mitsuba's lookup at each row's centre. (Its average over the row's band, which keeps the
  // integral over runs of rows, smooths once more on top of envgi's own bilinear lookup: it put
  // teapot-glass's fireplace region 0.14% off Mitsuba, against 0.11% for point values.)
  for (int j = 0; j < h; ++j) {
    // Mitsuba's row coordinate at this row's centre: in [0.5 (h-1)/h, h - 1), so j0 + 1 < h.
    double y = (double(j) + 0.5) * double(h - 1) / double(h);
    int j0 = std::min(int(y), h - 2);
    float t = float(y - double(j0));
    for (int x = 0; x < w; ++x) out.set(x, j, src.at(x, j0) * (1.f - t) + src.at(x, j0 + 1) * t);
  }
  return out;
}

EnvironmentMap EnvironmentMap::loadProbe(const std::string& path, ProbeLayout layout, const EnvironmentMapOptions& opts) {
  Image probe = loadImage(path);
  size_t invalid = 0;
  Image map;
  try {
    map = probeToLatLong(probe, layout, {}, &invalid);
  } catch (const std::runtime_error& e) {
    throw std::runtime_error("light probe '" + path + "': " + e.what());
  }
  if (invalid > 0)
    spdlog::warn("light probe '{}': {} NaN, infinite or negative channel values replaced with 0", path, invalid);
  spdlog::info("light probe '{}' ({}, {}x{}) resampled to a {}x{} lat-long map", path, probeLayoutName(layout),
               probe.width, probe.height, map.width, map.height);
  EnvironmentMap env(std::move(map), opts, path);
  env.invalid_ += invalid;  // the probe's, replaced before resampling: stats() reports them too
  return env;
}

EnvironmentMap EnvironmentMap::loadLayout(const std::string& path, const std::string& layout,
                                          const EnvironmentMapOptions& opts) {
  return layout == "latlong" ? load(path, opts) : loadProbe(path, parseProbeLayout(layout), opts);
}

EnvironmentMap EnvironmentMap::constant(Color radiance, const EnvironmentMapOptions& opts) {
  Image img(32, 16);
  for (int y = 0; y < img.height; ++y)
    for (int x = 0; x < img.width; ++x) img.set(x, y, radiance);
  return EnvironmentMap(std::move(img), opts, "constant");
}

std::vector<float> EnvironmentMap::samplingWeights(const Image& img, bool bilinear, bool misCompensation) {
  int w = img.width, h = img.height;
  std::vector<float> lum(size_t(w) * h);
  for (size_t i = 0; i < lum.size(); ++i) lum[i] = luminance(img.rgb[i * 3], img.rgb[i * 3 + 1], img.rgb[i * 3 + 2]);
  std::vector<float> weight(lum.size());
  if (bilinear) {
    // The average of the bilinear lookup over each pixel: the separable [1/8, 3/4, 1/8] filter
    // of the pixels (wrapping in u, clamped in v), the pixel's share of the lookup's integral.
    // Sampling then places the point inside the pixel by the lookup itself
    // (EnvironmentMapView::warpInPixel), so that the density is proportional to what eval()
    // returns, and positive wherever it is.
    std::vector<float> tmp(lum.size());
    for (int y = 0; y < h; ++y)
      for (int x = 0; x < w; ++x) {
        int xl = (x + w - 1) % w, xr = (x + 1) % w;
        const float* row = &lum[size_t(y) * w];
        tmp[size_t(y) * w + x] = 0.125f * row[xl] + 0.75f * row[x] + 0.125f * row[xr];
      }
    for (int y = 0; y < h; ++y) {
      int yu = std::max(y - 1, 0), yd = std::min(y + 1, h - 1);
      for (int x = 0; x < w; ++x)
        weight[size_t(y) * w + x] =
            0.125f * tmp[size_t(yu) * w + x] + 0.75f * tmp[size_t(y) * w + x] + 0.125f * tmp[size_t(yd) * w + x];
    }
  } else {
    weight = lum;
  }
  if (misCompensation) {
    double sum = 0.0, sa = 0.0;
    for (int y = 0; y < h; ++y) {
      double s = rowSinTheta(y, h);
      for (int x = 0; x < w; ++x) sum += weight[size_t(y) * w + x] * s;
      sa += s * w;
    }
    float mean = sa > 0.0 ? float(sum / sa) : 0.f;
    std::vector<float> comp(weight.size());
    bool any = false;
    for (size_t i = 0; i < weight.size(); ++i) {
      comp[i] = std::max(weight[i] - mean, 0.f);
      any = any || comp[i] > 0.f;
    }
    // A constant map compensates to nothing; keep the plain density then (Karlik et al. do too).
    if (any) weight.swap(comp);
  }
  for (int y = 0; y < h; ++y) {
    float s = rowSinTheta(y, h);
    for (int x = 0; x < w; ++x) weight[size_t(y) * w + x] *= s;  // Algorithm 1's row weighting by sin(theta)
  }
  return weight;
}

EnvironmentMap::EnvironmentMap(Image img, const EnvironmentMapOptions& opts, const std::string& name)
    : width_(img.width), height_(img.height), opts_(opts) {
  if (!(opts.scale >= 0.f) || !std::isfinite(opts.scale))
    throw std::runtime_error("environment map '" + name + "': scale must be a finite number >= 0");
  invalid_ = zeroInvalidRadiance(img);
  texels_.resize(size_t(width_) * height_ * 4);
  setLookupRgb(img);
  for (size_t i = 0; i < size_t(width_) * height_; ++i)
    texels_[i * 4 + 3] = luminance(texels_[i * 4], texels_[i * 4 + 1], texels_[i * 4 + 2]);
  if (invalid_ > 0)
    spdlog::warn("environment map '{}': {} NaN, infinite or negative channel values replaced with 0", name, invalid_);
  std::vector<float> weight = samplingWeights(img, opts.bilinear, opts.misCompensation);
  dist_ = PiecewiseConstant2D(weight.data(), img.width, img.height);
  alias_ = AliasTable(weight.data(), weight.size());
  // A black map leaves the product strategy to Algorithm 1's (uniform) fallback.
  if (dist_.integral() > 0.f) product_ = CosineProduct(weight.data(), img.width, img.height);
  if (opts.bilinear) warpBits_ = pixelsToWarp(view());
  // The quadtree baseline balances plain map power, never compensated power.
  std::vector<float> plain = opts.misCompensation ? samplingWeights(img, opts.bilinear, false) : weight;
  adaptive_ = AdaptiveQuadtree(plain.data(), img.width, img.height, opts.adaptiveLeaves);
  if (opts.misCompensation) emission_ = AliasTable(plain.data(), plain.size());
  buildAlgorithm1Table();
  if (dist_.integral() <= 0.f) spdlog::warn("environment map '{}' is black everywhere: a light of zero power", name);
}

Image EnvironmentMap::image() const {
  Image out(width_, height_);
  for (int y = 0; y < height_; ++y)
    for (int x = 0; x < width_; ++x) out.set(x, y, texelAt(x, y));
  return out;
}

void EnvironmentMap::setPoints(std::vector<DirectionalLight> points) {
  double total = 0.0;
  for (const DirectionalLight& d : points) total += std::max(0.f, luminance(d.irradiance));
  double acc = 0.0;
  for (DirectionalLight& d : points) {
    d.pmf = total > 0.0 ? float(std::max(0.f, luminance(d.irradiance)) / total) : 1.f / float(points.size());
    acc += d.pmf;
    d.cdf = float(acc);
  }
  if (!points.empty()) points.back().cdf = 1.f;  // a draw never falls past the last light
  points_ = std::move(points);
}

void EnvironmentMap::setPlacement(float scale, const Transform& toWorld) {
  if (!(scale >= 0.f) || !std::isfinite(scale)) throw std::runtime_error("environment scale must be a non-negative number");
  opts_.scale = scale;
  opts_.toWorld = toWorld;
}

EnvironmentMapView EnvironmentMap::view() const {
  EnvironmentMapView v;
  v.rowsFromPoles = rowsFromPoles_;
  v.texels = texels_.data();
  v.width = width_;
  v.height = height_;
  v.scale = opts_.scale;
  v.bilinear = opts_.bilinear;
  v.toWorld = opts_.toWorld;
  v.dist = dist_.view();
  v.paperDist = paperDist_.view();
  v.alias = alias_.view();
  v.emission = opts_.misCompensation ? emission_.view() : v.alias;
  v.adaptive = adaptive_.view();
  v.product = product_.view();
  v.warpBits = warpBits_.empty() ? nullptr : warpBits_.data();
  v.points = points_.empty() ? nullptr : points_.data();
  v.pointCount = int(points_.size());
  return v;
}

float EnvironmentMap::luminancePower() const {
  double sum = 0.0;
  int w = width_, h = height_;
  for (int y = 0; y < h; ++y) {
    double dA = pixelSolidAngle(y, w, h);
    // The density's luminance: for a file's rows on Mitsuba's grid, resampled to pixel centres.
    for (int x = 0; x < w; ++x) sum += texels_[(size_t(y) * w + x) * 4 + 3] * dA;
  }
  return float(sum * opts_.scale);
}

EnvironmentMapStats EnvironmentMap::stats() const {
  EnvironmentMapStats st;
  int w = width_, h = height_;
  st.width = w;
  st.height = h;
  st.invalidPixels = invalid_;
  st.channelMin = Color(INFINITY);
  st.channelMax = Color(-INFINITY);
  std::vector<float> lum(size_t(w) * h), energy(size_t(w) * h);
  double power[3] = {0, 0, 0}, lumSum = 0.0, saSum = 0.0;
  for (int y = 0; y < h; ++y) {
    double dA = pixelSolidAngle(y, w, h), s = dA;
    for (int x = 0; x < w; ++x) {
      Color c = texelAt(x, y) * opts_.scale;
      st.channelMin = vmin(st.channelMin, c);
      st.channelMax = vmax(st.channelMax, c);
      for (int k = 0; k < 3; ++k) power[k] += c[k] * dA;
      float l = luminance(c);
      lum[size_t(y) * w + x] = l;
      energy[size_t(y) * w + x] = float(l * s);
      lumSum += l * s;
      saSum += s;
    }
  }
  st.power = Color(float(power[0]), float(power[1]), float(power[2]));
  st.lumMeanSolidAngle = float(lumSum / saSum);
  std::vector<float> sorted = lum;
  std::sort(sorted.begin(), sorted.end());
  st.lumMin = sorted.front();
  st.lumMax = sorted.back();
  st.lumMedian = sorted[sorted.size() / 2];
  // Brightest 1% by luminance; their share of the solid-angle-weighted power.
  std::vector<size_t> idx(lum.size());
  std::iota(idx.begin(), idx.end(), size_t(0));
  size_t top = std::max<size_t>(1, lum.size() / 100);
  std::nth_element(idx.begin(), idx.begin() + top, idx.end(), [&](size_t a, size_t b) { return lum[a] > lum[b]; });
  double topSum = 0.0;
  for (size_t i = 0; i < top; ++i) topSum += energy[idx[i]];
  st.top1PercentEnergy = lumSum > 0.0 ? float(topSum / lumSum) : 0.f;
  return st;
}

}  // namespace envgi
