#include "envmap/LightProbe.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "envmap/EnvironmentMapView.h"

namespace envgi {

ProbeLayout parseProbeLayout(const std::string& name) {
  if (name == "angular") return ProbeLayout::Angular;
  if (name == "mirrorball") return ProbeLayout::MirrorBall;
  if (name == "cross") return ProbeLayout::Cross;
  throw std::runtime_error("unknown light-probe layout '" + name + "' (angular, mirrorball, cross)");
}

const char* probeLayoutName(ProbeLayout layout) {
  switch (layout) {
    case ProbeLayout::Angular: return "angular map";
    case ProbeLayout::MirrorBall: return "mirror ball";
    case ProbeLayout::Cross: return "cube cross";
  }
  return "?";
}

CubeFacePoint cubeFacePoint(Vec3f d, bool upright) {
  float ax = std::fabs(d.x), ay = std::fabs(d.y), az = std::fabs(d.z);
  if (az >= ax && az >= ay) {
    if (d.z < 0.f) return {5, {d.x / az, d.y / az}};
    return upright ? CubeFacePoint{4, {-d.x / az, d.y / az}} : CubeFacePoint{4, {d.x / az, -d.y / az}};
  }
  if (ax >= ay) return d.x > 0.f ? CubeFacePoint{0, {d.z / ax, d.y / ax}} : CubeFacePoint{1, {-d.z / ax, d.y / ax}};
  return d.y > 0.f ? CubeFacePoint{2, {d.x / ay, d.z / ay}} : CubeFacePoint{3, {d.x / ay, -d.z / ay}};
}

Vec3f cubeFaceDirection(int face, Vec2f st, bool upright) {
  float s = st.x, t = st.y;
  Vec3f d;
  switch (face) {
    case 0: d = {1.f, t, s}; break;
    case 1: d = {-1.f, t, -s}; break;
    case 2: d = {s, 1.f, t}; break;
    case 3: d = {s, -1.f, -t}; break;
    case 4: d = upright ? Vec3f(-s, t, 1.f) : Vec3f(s, -t, 1.f); break;
    default: d = {s, t, -1.f}; break;
  }
  return normalize(d);
}

void crossCell(int face, bool vertical, int* column, int* row) {
  // +X, -X, +Y, -Y, +Z, -Z: right, left, up, down, backward, forward.
  static const int kVertical[6][2] = {{2, 1}, {0, 1}, {1, 0}, {1, 2}, {1, 3}, {1, 1}};
  static const int kHorizontal[6][2] = {{2, 1}, {0, 1}, {1, 0}, {1, 2}, {3, 1}, {1, 1}};
  const int* c = vertical ? kVertical[face] : kHorizontal[face];
  *column = c[0];
  *row = c[1];
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

// Bilinear between pixel centres of the cell [x0, x0 + w) x [y0, y0 + h) of the image, (x, y)
// in pixels of the cell, clamped at the cell's edges so that no other cube face (or a cross's
// empty cells) bleeds in; and over the texels that inside(px, py) keeps only, so that a disk's
// rim is not darkened by the corners outside it (usually black, or the photograph's backdrop).
// Where it keeps none of the four, all four count.
template <class Inside>
Color bilinearInCell(const Image& img, int x0, int y0, int w, int h, float x, float y, Inside inside) {
  float fx = x - 0.5f, fy = y - 0.5f;
  float xf = std::floor(fx), yf = std::floor(fy);
  float tx = fx - xf, ty = fy - yf;
  int xs[2] = {std::clamp(int(xf), 0, w - 1), std::clamp(int(xf) + 1, 0, w - 1)};
  int ys[2] = {std::clamp(int(yf), 0, h - 1), std::clamp(int(yf) + 1, 0, h - 1)};
  float wx[2] = {1.f - tx, tx}, wy[2] = {1.f - ty, ty};
  Color sum(0.f), plain(0.f);
  float weight = 0.f;
  for (int j = 0; j < 2; ++j)
    for (int i = 0; i < 2; ++i) {
      Color c = img.at(x0 + xs[i], y0 + ys[j]) * (wx[i] * wy[j]);
      plain += c;
      if (!inside(xs[i], ys[j])) continue;
      sum += c;
      weight += wx[i] * wy[j];
    }
  return weight > 0.f ? sum * (1.f / weight) : plain;
}

std::string sizeText(const Image& img) { return std::to_string(img.width) + "x" + std::to_string(img.height); }

}  // namespace

Image probeToLatLong(const Image& probe, ProbeLayout layout, const ProbeConversion& opts, size_t* invalid) {
  bool cross = layout == ProbeLayout::Cross;
  bool vertical = probe.width * 4 == probe.height * 3;
  int face = probe.width / (vertical ? 3 : 4);  // a cross's face size
  if (cross) {
    if (!(vertical || probe.width * 3 == probe.height * 4) || face < 1 || probe.width % (vertical ? 3 : 4) != 0)
      throw std::runtime_error("a cube cross is 3N x 4N (vertical) or 4N x 3N (horizontal) pixels, not " + sizeText(probe));
  } else if (probe.width != probe.height || probe.width < 2) {
    throw std::runtime_error("a light probe is a square image of at least 2x2, not " + sizeText(probe) +
                             (probe.width == 2 * probe.height ? " (this looks like a lat-long map already)" : ""));
  }
  // Bounds that keep a mistyped option from asking for gigabytes or hours.
  int natural = cross ? 4 * face : 2 * probe.width;
  int width = opts.width > 0 ? opts.width : std::min(std::max(natural, 2), kMaxProbeMapWidth);
  if (width < 2 || width % 2 != 0 || width > kMaxProbeMapWidth)
    throw std::runtime_error("the lat-long width must be even, from 2 to " + std::to_string(kMaxProbeMapWidth) +
                             ", not " + std::to_string(width));
  if (opts.samplesPerSide > kMaxProbeSamplesPerSide)
    throw std::runtime_error("at most " + std::to_string(kMaxProbeSamplesPerSide) + " x " +
                             std::to_string(kMaxProbeSamplesPerSide) + " lookups a map pixel, not " +
                             std::to_string(opts.samplesPerSide));
  int height = width / 2;
  // Probe pixels across one map pixel, where the probe is sharpest: the disks span pi from
  // centre to rim in width / 2 pixels, linearly for the angular map, and a mirror ball spreads
  // its centre by pi / 2 more; a cube face spans pi / 2 in N pixels at its centre.
  float perPixel = cross ? 4.f * float(face) / float(width)
                         : float(probe.width) / float(height) * (layout == ProbeLayout::Angular ? 0.5f : 0.25f * kPi);
  int n = opts.samplesPerSide > 0 ? opts.samplesPerSide
                                  : std::clamp(int(std::ceil(perPixel - 1e-3f)), 1, kMaxProbeSamplesPerSide);

  Image clean = probe;
  size_t bad = zeroInvalidRadiance(clean);
  if (invalid) *invalid = bad;
  auto inDisk = [&](int px, int py) {
    float dx = (float(px) + 0.5f) / float(probe.width) * 2.f - 1.f, dy = (float(py) + 0.5f) / float(probe.height) * 2.f - 1.f;
    return dx * dx + dy * dy <= 1.f;
  };

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
          Vec3f d = latLongToProbeFrame(EnvironmentMapView::uvToDir(uv));
          Color c;
          if (cross) {
            CubeFacePoint f = cubeFacePoint(d, !vertical);
            int col, row;
            crossCell(f.face, vertical, &col, &row);
            // Image rows run down, t up.
            c = bilinearInCell(clean, col * face, row * face, face, face, (f.st.x + 1.f) * 0.5f * float(face),
                               (1.f - f.st.y) * 0.5f * float(face), [](int, int) { return true; });
          } else {
            Vec2f p = probeDiskPoint(layout, d);
            float r = std::sqrt(p.x * p.x + p.y * p.y);
            if (r > rimMax) p = p * (rimMax / r);
            // Image row 0 is the disk's top (y = +1).
            c = bilinearInCell(clean, 0, 0, probe.width, probe.height, (p.x + 1.f) * 0.5f * float(probe.width),
                               (1.f - p.y) * 0.5f * float(probe.height), inDisk);
          }
          // Each lookup weighted before the sum, so that values near FLT_MAX cannot add up to inf.
          sum += c * (1.f / float(n * n));
        }
      out.set(x, y, sum);
    }
  return out;
}

}  // namespace envgi
