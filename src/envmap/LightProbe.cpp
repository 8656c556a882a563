#include "envmap/LightProbe.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "envmap/EnvironmentMapView.h"

namespace envgi {

ProbeLayout parseProbeLayout(const std::string& name) {
  if (name == "angular") return ProbeLayout::Angular;
  if (name == "mirrorball") return ProbeLayout::MirrorBall;
  throw std::runtime_error("unknown light-probe layout '" + name + "' (angular, mirrorball)");
}

Vec2f probeDiskPoint(ProbeLayout layout, Vec3f d) {
  // theta from forward (-Z) by atan2, which keeps its digits near both poles (acos does not).
  float side = std::sqrt(d.x * d.x + d.y * d.y);
  float theta = std::atan2(side, -d.z);
  float rho = layout == ProbeLayout::Angular ? theta * kInvPi : std::sin(0.5f * theta);
  if (!(side > 0.f)) return {0.f, d.z > 0.f ? rho : 0.f};  // straight back: any point of the rim
  float across = layout == ProbeLayout::MirrorBall ? -1.f : 1.f;  // the ball mirrors left and right
  return {across * d.x / side * rho, d.y / side * rho};
}

Vec3f probeDiskDirection(ProbeLayout layout, Vec2f p) {
  float rho = std::min(std::sqrt(p.x * p.x + p.y * p.y), 1.f);
  float theta = layout == ProbeLayout::Angular ? rho * kPi : 2.f * std::asin(rho);
  float s = std::sin(theta);
  if (!(rho > 0.f)) return {0.f, 0.f, -1.f};
  float across = layout == ProbeLayout::MirrorBall ? -1.f : 1.f;
  return {across * p.x / rho * s, p.y / rho * s, -std::cos(theta)};
}

namespace {

// Bilinear between pixel centres, clamped at the image's edges, (x, y) in pixels, over the
// texels inside the disk only: those outside (usually black, or the photograph's backdrop)
// would darken the rim, which holds the whole backward direction.
Color bilinearInDisk(const Image& img, const std::vector<float>& rgb, float x, float y) {
  float fx = x - 0.5f, fy = y - 0.5f;
  float x0f = std::floor(fx), y0f = std::floor(fy);
  float tx = fx - x0f, ty = fy - y0f;
  int xs[2] = {std::clamp(int(x0f), 0, img.width - 1), std::clamp(int(x0f) + 1, 0, img.width - 1)};
  int ys[2] = {std::clamp(int(y0f), 0, img.height - 1), std::clamp(int(y0f) + 1, 0, img.height - 1)};
  float wx[2] = {1.f - tx, tx}, wy[2] = {1.f - ty, ty};
  Color sum(0.f), plain(0.f);
  float weight = 0.f;
  for (int j = 0; j < 2; ++j)
    for (int i = 0; i < 2; ++i) {
      const float* q = &rgb[(size_t(ys[j]) * img.width + xs[i]) * 3];
      Color c(q[0], q[1], q[2]);
      float w = wx[i] * wy[j];
      plain += c * w;
      float dx = (float(xs[i]) + 0.5f) / float(img.width) * 2.f - 1.f, dy = (float(ys[j]) + 0.5f) / float(img.height) * 2.f - 1.f;
      if (dx * dx + dy * dy > 1.f) continue;
      sum += c * w;
      weight += w;
    }
  return weight > 0.f ? sum * (1.f / weight) : plain;
}

}  // namespace

Image probeToLatLong(const Image& probe, ProbeLayout layout, const ProbeConversion& opts, size_t* invalid) {
  if (probe.width != probe.height || probe.width < 2)
    throw std::runtime_error("a light probe is a square image of at least 2x2, not " + std::to_string(probe.width) + "x" +
                             std::to_string(probe.height) +
                             (probe.width == 2 * probe.height ? " (this looks like a lat-long map already)" : ""));
  // Bounds that keep a mistyped option from asking for gigabytes or hours.
  int width = opts.width > 0 ? opts.width : std::min(2 * probe.width, kMaxProbeMapWidth);
  if (width < 2 || width % 2 != 0 || width > kMaxProbeMapWidth)
    throw std::runtime_error("the lat-long width must be even, from 2 to " + std::to_string(kMaxProbeMapWidth) +
                             ", not " + std::to_string(width));
  if (opts.samplesPerSide > kMaxProbeSamplesPerSide)
    throw std::runtime_error("at most " + std::to_string(kMaxProbeSamplesPerSide) + " x " +
                             std::to_string(kMaxProbeSamplesPerSide) + " lookups a map pixel, not " +
                             std::to_string(opts.samplesPerSide));
  int height = width / 2;
  // Probe pixels across one map pixel: the probe spans pi from its centre to its rim in width / 2
  // pixels, linearly for the angular map; a mirror ball spreads the centre by pi / 2 more.
  float perPixel = float(probe.width) / float(height) * (layout == ProbeLayout::Angular ? 0.5f : 0.25f * kPi);
  int n = opts.samplesPerSide > 0 ? opts.samplesPerSide
                                  : std::clamp(int(std::ceil(perPixel - 1e-3f)), 1, kMaxProbeSamplesPerSide);

  std::vector<float> rgb = probe.rgb;
  size_t bad = 0;
  for (float& v : rgb)
    if (!std::isfinite(v) || v < 0.f) v = 0.f, ++bad;
  if (invalid) *invalid = bad;

  // Lookups stay half a probe pixel inside the rim, where the image's corners (outside the
  // disk, usually black) would bleed in.
  float rimMax = 1.f - 1.f / float(probe.width);
  Image out(width, height);
  for (int y = 0; y < height; ++y)
    for (int x = 0; x < width; ++x) {
      Color sum(0.f);
      for (int j = 0; j < n; ++j)
        for (int i = 0; i < n; ++i) {
          Vec2f uv((float(x) + (float(i) + 0.5f) / float(n)) / float(width),
                   (float(y) + (float(j) + 0.5f) / float(n)) / float(height));
          Vec2f p = probeDiskPoint(layout, latLongToProbeFrame(EnvironmentMapView::uvToDir(uv)));
          float r = std::sqrt(p.x * p.x + p.y * p.y);
          if (r > rimMax) p = p * (rimMax / r);
          // Image row 0 is the disk's top (y = +1).
          // Each lookup weighted before the sum, so that values near FLT_MAX cannot add up to inf.
          sum += bilinearInDisk(probe, rgb, (p.x + 1.f) * 0.5f * float(probe.width), (1.f - p.y) * 0.5f * float(probe.height)) *
                 (1.f / float(n * n));
        }
      out.set(x, y, sum);
    }
  return out;
}

}  // namespace envgi
