// An HDR lat-long environment map as plain data: radiance lookup by direction and the
// sampling strategies the paper compares. Host and device share this code.
//
// Direction convention (the same as Mitsuba 3's `envmap` emitter): in the map's own frame
// +Y is up; u = atan2(x, -z) / 2pi (wrapped to [0,1)), v = acos(y) / pi, so row 0 is the
// zenith, the centre column (u = 0.5) looks along +Z and u = 0.25 along +X. to_world
// rotates that frame into the scene.
#pragma once

#include "core/Atan2.h"
#include "core/Frame.h"
#include "core/Transform.h"
#include "envmap/AdaptiveQuadtree.h"
#include "envmap/CosineProduct.h"
#include "sampling/AliasTable.h"
#include "sampling/PiecewiseConstant2D.h"
#include "sampling/Warp.h"

namespace envgi {

enum class EnvStrategy : int {
  Uniform = 0,     // uniform over the sphere
  Cosine = 1,      // cosine-weighted about a normal
  Importance = 2,  // Algorithm 1: marginal/conditional CDFs, binary search
  Alias = 3,       // the same density through an alias table
  Adaptive = 4,    // energy-balanced quadtree baseline
  Points = 5,      // the collapsed map, one of its lights drawn a light sample by its share
  Product = 6,     // Algorithm 1's density times a cosine bound about the normal (CosineProduct)
  // The collapsed map as the paper means it (Section 2.2): every one of its N lights, each with
  // its shadow ray, at every shading point; one set for the whole render, so neighbouring
  // pixels share one estimate (biased, no noise from the map). Not a sampling density:
  // next-event estimation adds the sum itself (collapsedMapLighting) and draws nothing here.
  PointsAll = 7,
  // Algorithm 1 exactly: the file's pixel luminance x sin(theta) at its row's centre, constant
  // over the pixel, on pixel rows, and uniform inside the pixel (`importance`). Importance
  // above is the density matched to the bilinear lookup (`importance-bilinear`).
  Algorithm1 = 8,
};

// Strategies whose map light comes from the collapsed map's delta lights, which no BSDF-sampled
// direction can find.
ENVGI_INLINE bool isCollapsedMap(EnvStrategy s) { return s == EnvStrategy::Points || s == EnvStrategy::PointsAll; }

// One light of the collapsed map (the paper's Section 2): a direction and the irradiance it
// delivers to a surface facing it, E = L(w) / (pdf(w) N) for weighted sampling, or the power
// of a median-cut region.
struct DirectionalLight {
  Vec3f dir;  // world space, towards the light
  Color irradiance;
  float pmf = 0.f;  // chance next-event estimation picks it: by luminance of its irradiance
  float cdf = 0.f;  // sum of the pmfs up to and including this one
  // Its share of the sphere (the paper's Delta Phi_p weight): 1 / (p N) for a weighted-sampling
  // draw, the region's solid angle for median cut. The shares sum to 4 pi in expectation.
  float solidAngle = 0.f;
};

struct EnvSample {
  Vec3f dir;       // world space, pointing away from the scene
  Color radiance;  // scaled radiance arriving from dir
  float pdf = 0.f; // solid angle; for a delta sample (a collapsed-map light) its selection pmf
  Vec2f uv;
  bool delta = false;
};

struct EnvironmentMapView {
  // width * height texels of 4 floats: the lookup's r, g, b (sanitised: finite, >= 0) and the
  // luminance the sampling density follows (the tables and the in-pixel warp), side by side so
  // that a warp and the lookup next to it share cache lines.
  const float* texels = nullptr;
  int width = 0, height = 0;
  // Mitsuba's row placement: the lookup puts row j at v = j / (height - 1), from pole to pole,
  // while the density's luminance (resampled) sits at pixel centres, v = (j + 0.5) / height.
  bool rowsFromPoles = false;
  float scale = 1.f;
  bool bilinear = true;
  Transform toWorld;
  PiecewiseConstant2DView dist;  // func = luminance x sin(theta) per pixel
  PiecewiseConstant2DView paperDist;  // Algorithm 1's own table (EnvStrategy::Algorithm1)
  AliasTableView alias;          // over all pixels, same weights as dist
  // Light leaving the map, by plain luminance x sin(theta): the same table as `alias` unless
  // MIS compensation made dist and alias sample max(L - mean, 0), which misses dim directions.
  AliasTableView emission;
  AdaptiveQuadtreeView adaptive;
  CosineProductView product;  // over the same weights as dist
  const uint32_t* warpBits = nullptr;  // bit per pixel: draws inside it follow the lookup (bilinear only)
  const DirectionalLight* points = nullptr;  // the collapsed map, when one was made
  int pointCount = 0;

  // d need not be unit: both atan2 calls see its components scaled alike.
  ENVGI_HD static Vec2f dirToUV(Vec3f d) {
    float u = polyAtan2(d.x, -d.z) * kInv2Pi;
    if (u < 0.f) u += 1.f;
    if (!(u < 1.f)) u = 0.f;
    // atan2 rather than acos: acos loses half its digits near the poles.
    float v = polyAtan2(std::sqrt(d.x * d.x + d.z * d.z), d.y) * kInvPi;
    return {u, v};
  }
  ENVGI_HD static Vec3f uvToDir(Vec2f uv) {
    float phi = 2.f * kPi * uv.x, theta = kPi * uv.y;
    float st = std::sin(theta);
    return {st * std::sin(phi), std::cos(theta), -st * std::cos(phi)};
  }

  // A texel's radiance. Index: what the texel's offset is counted in. 32 bits unsigned lets a
  // loop of lookups gather, for a map of at most 2^30 pixels (fitsUnsignedIndex).
  template <class Index = size_t>
  ENVGI_HD static Color texelIn(const float* texels, int width, int x, int y) {
    const Index i = (Index(y) * Index(width) + Index(x)) * Index(4);
    return {texels[i], texels[i + 1], texels[i + 2]};
  }
  ENVGI_HD bool fitsUnsignedIndex() const { return size_t(width) * size_t(height) <= (size_t(1) << 30); }

  // Bilinear between pixel centres, wrapping across the phi seam and clamping at the poles.
  ENVGI_HD Color lookupUV(Vec2f uv) const { return lookupIn(texels, width, height, rowsFromPoles, scale, bilinear, uv); }
  // lookupUV from the members it reads, passed one by one: a loop over many lookups holds them
  // in registers and vectorises.
  template <class Index = size_t>
  ENVGI_HD static Color lookupIn(const float* texels, int width, int height, bool rowsFromPoles, float scale,
                                 bool bilinear, Vec2f uv) {
    if (!bilinear) {
      int x = clampi(int(uv.x * width), 0, width - 1), y = clampi(int(uv.y * height), 0, height - 1);
      return texelIn<Index>(texels, width, x, y) * scale;
    }
    float fx = uv.x * width - 0.5f, fy = rowsFromPoles ? uv.y * float(height - 1) : uv.y * height - 0.5f;
    float x0f = std::floor(fx), y0f = std::floor(fy);
    float tx = fx - x0f, ty = fy - y0f;
    int x0 = int(x0f), y0 = int(y0f);
    // u in [0,1) puts x0 in [-1, width - 1]: wrap by comparison, not by integer division.
    int xa = x0 < 0 ? x0 + width : (x0 >= width ? x0 - width : x0);
    int xb = xa + 1 < width ? xa + 1 : 0;
    int ya = clampi(y0, 0, height - 1), yb = clampi(y0 + 1, 0, height - 1);
    Color c = (texelIn<Index>(texels, width, xa, ya) * (1.f - tx) + texelIn<Index>(texels, width, xb, ya) * tx) *
                  (1.f - ty) +
              (texelIn<Index>(texels, width, xa, yb) * (1.f - tx) + texelIn<Index>(texels, width, xb, yb) * tx) * ty;
    return c * scale;
  }

  // The columns xs and rows ys of pixel (px, py) and its eight neighbours, wrapping in u and
  // clamping at the poles as lookupUV does; and their luminance, l[j][i] at (xs[i], ys[j]).
  ENVGI_HD void neighbourhood(int px, int py, int xs[3], int ys[3]) const { neighbourhoodIn(width, height, px, py, xs, ys); }
  ENVGI_HD static void neighbourhoodIn(int width, int height, int px, int py, int xs[3], int ys[3]) {
    xs[0] = px > 0 ? px - 1 : width - 1, xs[1] = px, xs[2] = px + 1 < width ? px + 1 : 0;
    ys[0] = py > 0 ? py - 1 : 0, ys[1] = py, ys[2] = py + 1 < height ? py + 1 : height - 1;
  }
  ENVGI_HD void neighbourhoodLuminance(int px, int py, float l[3][3]) const {
    neighbourhoodLuminanceIn(texels, width, height, px, py, l);
  }
  // The members' forms of these functions take what they read as arguments (the static ...In
  // forms), so that a loop over many draws holds it in registers; Index as in texelIn.
  template <class Index = size_t>
  ENVGI_HD static void neighbourhoodLuminanceIn(const float* texels, int width, int height, int px, int py,
                                                float l[3][3]) {
    int xs[3], ys[3];
    neighbourhoodIn(width, height, px, py, xs, ys);
    for (int j = 0; j < 3; ++j)
      for (int i = 0; i < 3; ++i)
        l[j][i] = texels[(Index(ys[j]) * Index(width) + Index(xs[i])) * Index(4) + Index(3)];
  }
  // The bilinear lookup's luminance over pixel (px, py) is four bilinear patches meeting on a
  // 3 x 3 lattice: v[j][i] at x = i / 2, y = j / 2 across the pixel (its corners, the midpoints
  // of its edges, its centre), each the mean of the pixels around that point, wrapping in u and
  // clamping at the poles as lookupUV does.
  ENVGI_HD void pixelLattice(int px, int py, float v[3][3]) const { pixelLatticeIn(texels, width, height, px, py, v); }
  template <class Index = size_t>
  ENVGI_HD static void pixelLatticeIn(const float* texels, int width, int height, int px, int py, float v[3][3]) {
    float l[3][3];
    neighbourhoodLuminanceIn<Index>(texels, width, height, px, py, l);
    for (int j = 0; j < 3; ++j)
      for (int i = 0; i < 3; ++i) {
        // The pixels around lattice point (i, j): the centre one, and the neighbour on the
        // point's side across and down where the point lies on an edge or a corner.
        float s = l[1][1] + (i != 1 ? l[1][i] : 0.f) + (j != 1 ? l[j][1] : 0.f) + (i != 1 && j != 1 ? l[j][i] : 0.f);
        v[j][i] = s / float((i != 1 ? 2 : 1) * (j != 1 ? 2 : 1));
      }
  }

  // The pixel uv falls in, and where in it: the point's fraction across and down, in [0, 1].
  struct PixelPoint {
    int x, y;
    Vec2f f;
  };
  ENVGI_HD PixelPoint pixelPoint(Vec2f uv) const { return pixelPointIn(width, height, uv); }
  ENVGI_HD static PixelPoint pixelPointIn(int width, int height, Vec2f uv) {
    PixelPoint p;
    p.x = clampi(int(uv.x * float(width)), 0, width - 1);
    p.y = clampi(int(uv.y * float(height)), 0, height - 1);
    p.f = {clampf(uv.x * float(width) - float(p.x), 0.f, 1.f), clampf(uv.y * float(height) - float(p.y), 0.f, 1.f)};
    return p;
  }

  // A point uniform inside its pixel (uv from a pixel-constant density) moved so that it follows
  // the bilinear lookup's luminance inside that pixel: x by the patches' marginal, then y given
  // x, each by inverting a piecewise-linear cdf, so that stratified (u1, u2) stay stratified.
  // With the pixel chosen by the lookup's average over it, the density is then proportional to
  // the lookup itself, as Mitsuba's piecewise-bilinear warp is; a pixel-constant density is
  // not, next to a small sun.
  // *rel: its density at the point, as densityInPixel gives it, from the same lattice.
  ENVGI_HD Vec2f warpInPixel(const PixelPoint& p, float* rel) const {
    return warpInPixelIn(texels, width, height, p, rel);
  }
  // Settle false leaves out insidePixel's last steps, which a loop over many draws cannot
  // vectorise: its answer is warpInPixel's where each coordinate lands in pixel p (insidePixel's
  // steps then take none), and is redone by warpInPixel elsewhere.
  template <class Index = size_t, bool Settle = true>
  ENVGI_HD static Vec2f warpInPixelIn(const float* texels, int width, int height, const PixelPoint& p, float* rel) {
    float v[3][3];
    pixelLatticeIn<Index>(texels, width, height, p.x, p.y, v);
    float x = sampleTwoLinearPieces(p.f.x, v[0][0] + 2.f * v[1][0] + v[2][0], v[0][1] + 2.f * v[1][1] + v[2][1],
                                    v[0][2] + 2.f * v[1][2] + v[2][2]);
    float y = sampleTwoLinearPieces(p.f.y, twoLinearPieces(x, v[0][0], v[0][1], v[0][2]),
                                    twoLinearPieces(x, v[1][0], v[1][1], v[1][2]),
                                    twoLinearPieces(x, v[2][0], v[2][1], v[2][2]));
    Vec2f w(insidePixel<Settle>(p.x, x, width), insidePixel<Settle>(p.y, y, height));
    *rel = latticeDensity(v, pixelPointIn(width, height, w).f);  // the same pixel: insidePixel keeps it there
    return w;
  }

  // warpInPixel's density at a point relative to uniform over its pixel: the lookup's luminance
  // over its mean on the pixel (1 on a black pixel, which warpInPixel leaves uniform).
  ENVGI_HD float densityInPixel(const PixelPoint& p) const {
    float v[3][3];
    pixelLattice(p.x, p.y, v);
    return latticeDensity(v, p.f);
  }
  // The lookup over a pixel's lattice at fraction f of the pixel, over its mean there.
  ENVGI_HD static float latticeDensity(const float v[3][3], Vec2f f) {
    float row[3], mean = 0.f;
    for (int j = 0; j < 3; ++j) {
      row[j] = twoLinearPieces(f.x, v[j][0], v[j][1], v[j][2]);
      mean += (j == 1 ? 2.f : 1.f) * (v[j][0] + 2.f * v[j][1] + v[j][2]);
    }
    mean *= 1.f / 16.f;
    return mean > 0.f ? twoLinearPieces(f.y, row[0], row[1], row[2]) / mean : 1.f;
  }

  // For the strategies that pick a pixel from a table (importance, alias, product): with
  // bilinear lookup, the point inside the pixel follows the lookup where the pixel is marked,
  // and *pdfUV takes its factor.
  ENVGI_HD bool warps(const PixelPoint& p) const { return warpBits && warpBitIn(warpBits, width, p) == 1u; }
  // The bit as a number: its conversion to bool is one that GCC does not vectorise.
  template <class Index = size_t>
  ENVGI_HD static uint32_t warpBitIn(const uint32_t* warpBits, int width, const PixelPoint& p) {
    const Index i = Index(p.y) * Index(width) + Index(p.x);
    return (warpBits[i >> 5] >> (i & 31)) & 1u;
  }
  ENVGI_HD bool warpsAt(Vec2f uv) const { return warps(pixelPoint(uv)); }
  ENVGI_HD Vec2f placeInPixel(Vec2f uv, float* pdfUV) const {
    PixelPoint p = pixelPoint(uv);
    if (!warps(p)) return uv;
    float rel;
    Vec2f w = warpInPixel(p, &rel);
    *pdfUV *= rel;
    return w;
  }
  ENVGI_HD float pdfInPixel(Vec2f uv) const {
    PixelPoint p = pixelPoint(uv);
    return warps(p) ? densityInPixel(p) : 1.f;
  }

  ENVGI_HD Vec3f toLocal(Vec3f worldDir) const { return normalize(toWorld.inverseVector(worldDir)); }
  // toLocal up to a positive factor, a square root and a division cheaper: enough for dirToUV
  // and the product's normal buckets, which do not depend on the length.
  ENVGI_HD Vec3f toLocalUnnormalized(Vec3f worldDir) const { return toWorld.inverseVector(worldDir); }
  ENVGI_HD Vec3f fromLocal(Vec3f localDir) const { return normalize(toWorld.vector(localDir)); }

  // Where world direction d meets the map.
  ENVGI_HD Vec2f uvOf(Vec3f d) const { return dirToUV(toLocalUnnormalized(d)); }
  // Radiance arriving from world direction d.
  ENVGI_HD Color eval(Vec3f d) const { return lookupUV(uvOf(d)); }

  // Density in solid angle of the importance density at (u, v): p(u,v) / (2 pi^2 sin theta).
  // A pixel from an alias table over the map and a position inside it from the bits the choice
  // left over: 12 across, 11 down, each centred in its step so that float rounding never
  // carries a sample over the pixel's edge into its neighbour.
  ENVGI_HD Vec2f sampleTable(const AliasTableView& t, Vec2f u, float* pmf) const {
    float r;
    int i = t.sample(u, pmf, &r);
    int px = i % width, py = i / width;
    const Vec2f f = splitLeftover(r);
    return {(float(px) + f.x) / float(width), (float(py) + f.y) / float(height)};
  }

  // A density over (u, v) as a density in solid angle: dw = 2 pi^2 sin(theta) du dv; zero at
  // the poles, where the mapping degenerates.
  ENVGI_HD static float solidAnglePdf(float pdfUV, float v) {
    float st = std::sin(kPi * v);
    return st > 0.f ? pdfUV / (2.f * kPi * kPi * st) : 0.f;
  }

  // A direction for light leaving the map (photon emission), drawn by plain luminance even
  // where MIS compensation is on; pdf in solid angle.
  ENVGI_HD EnvSample sampleEmission(Vec2f u) const {
    EnvSample out;
    float pmf;
    out.uv = sampleTable(emission, u, &pmf);
    out.pdf = solidAnglePdf(pmf * float(width) * float(height), out.uv.y);
    out.dir = fromLocal(uvToDir(out.uv));
    out.radiance = out.pdf > 0.f ? lookupUV(out.uv) : Color(0.f);
    return out;
  }

  // Asks for the emission table's bin that sampleEmission(u) reads first (CPU only: the photon
  // pass prefetches a block of photons' bins, so that their misses overlap). Its texels were
  // tried too and cost more than they saved.
  void prefetchEmission(Vec2f u) const { prefetchLine(emission.bins + emission.column(u)); }

  // Asks for what evalWithPdf(s, worldDir, normal) reads from the map (host only: a batch of
  // directions prefetched before any is read overlaps its misses): the texel rows the lookup and
  // the in-pixel density read and, for product, its two cdf steps.
  // uv: where the direction meets the map (dirToUV's).
  void prefetchEvalWithPdf(EnvStrategy s, Vec2f uv, Vec3f normal) const {
    const PixelPoint p = pixelPoint(uv);
    int xs[3], ys[3];
    neighbourhood(p.x, p.y, xs, ys);
    for (int j = 0; j < 3; ++j) {  // 16-byte texels: the middle one shares a line with one of these but at the seam
      prefetchLine(texels + (size_t(ys[j]) * width + xs[0]) * 4);
      prefetchLine(texels + (size_t(ys[j]) * width + xs[2]) * 4);
    }
    if (strategyFor(s, normal) == EnvStrategy::Product) product.prefetchPdf(uv, toLocalUnnormalized(normal));
  }

  // Asks for the texel rows that drawing inside pixel (px, py) reads (warpInPixel's lattice,
  // the lookup) and its warp bit (CPU only).
  void prefetchPixel(int px, int py) const {
    int xs[3], ys[3];
    neighbourhood(px, py, xs, ys);
    for (int j = 0; j < 3; ++j) {
      prefetchLine(texels + (size_t(ys[j]) * width + xs[0]) * 4);
      prefetchLine(texels + (size_t(ys[j]) * width + xs[2]) * 4);
    }
    if (warpBits) prefetchLine(warpBits + ((size_t(py) * size_t(width) + size_t(px)) >> 5));
  }

  ENVGI_HD float importancePdfUV(Vec2f uv) const { return solidAnglePdf(dist.pdf(uv), uv.y); }

  // The strategy that draws for this normal: a zero normal (a BSDF that also transmits) means
  // the whole sphere, so cosine becomes uniform and product (like a map without its tables,
  // a black one) becomes Algorithm 1's density. sample() and pdf() both go through it.
  ENVGI_HD EnvStrategy strategyFor(EnvStrategy s, Vec3f normal) const {
    bool wholeSphere = lengthSq(normal) == 0.f;
    if (wholeSphere && s == EnvStrategy::Cosine) return EnvStrategy::Uniform;
    if (s == EnvStrategy::Product && (wholeSphere || !product.valid())) return EnvStrategy::Importance;
    return s;
  }

  // Draws a direction; `normal` (world space) is used by the cosine and product strategies
  // only. A zero normal (a BSDF that also transmits) means the whole sphere: the cosine strategy
  // then samples uniformly and the product strategy by Algorithm 1's density.
  ENVGI_HD EnvSample sample(EnvStrategy s, Vec2f u, Vec3f normal = Vec3f(0.f, 1.f, 0.f)) const {
    EnvSample out;
    Vec3f local;
    switch (strategyFor(s, normal)) {
      case EnvStrategy::Uniform: {
        local = sampleUniformSphere(u);
        out.pdf = uniformSpherePdf();
        out.uv = dirToUV(local);
        break;
      }
      case EnvStrategy::Cosine: {
        Frame f = Frame::fromNormal(normal);
        Vec3f w = f.toWorld(sampleCosineHemisphere(u));
        out.dir = normalize(w);
        out.pdf = cosineHemispherePdf(dot(out.dir, normal));
        out.uv = uvOf(out.dir);
        out.radiance = out.pdf > 0.f ? lookupUV(out.uv) : Color(0.f);
        return out;
      }
      case EnvStrategy::Importance: {
        float pdf2, inPixel = 1.f;
        out.uv = placeInPixel(dist.sample(u, &pdf2), &inPixel);
        local = uvToDir(out.uv);
        out.pdf = importancePdfUV(out.uv) * inPixel;
        break;
      }
      case EnvStrategy::Algorithm1: {
        float pdfUV;
        out.uv = paperDist.sample(u, &pdfUV);
        local = uvToDir(out.uv);
        out.pdf = solidAnglePdf(pdfUV, out.uv.y);
        break;
      }
      case EnvStrategy::Alias: {
        float pmf, inPixel = 1.f;
        out.uv = placeInPixel(sampleTable(alias, u, &pmf), &inPixel);
        local = uvToDir(out.uv);
        out.pdf = importancePdfUV(out.uv) * inPixel;
        break;
      }
      case EnvStrategy::Adaptive: {
        out.uv = adaptive.sample(u, &out.pdf);
        local = uvToDir(out.uv);
        break;
      }
      case EnvStrategy::Product: {
        float pdfUV;
        Vec2f uv;
        if (!product.sample(u, toLocalUnnormalized(normal), &uv, &pdfUV)) return out;
        return productSample(uv, pdfUV);
      }
      case EnvStrategy::Points: {
        // One light chosen by its share of the irradiance: radiance / pmf estimates sum_i f E_i.
        if (pointCount == 0) return out;
        int lo = 0, hi = pointCount - 1;
        while (lo < hi) {
          int mid = (lo + hi) / 2;
          if (points[mid].cdf > u.x) hi = mid;
          else lo = mid + 1;
        }
        int i = lo;
        out.dir = points[i].dir;
        out.pdf = points[i].pmf;
        out.radiance = points[i].irradiance;
        out.uv = uvOf(out.dir);
        out.delta = true;
        return out;
      }
      case EnvStrategy::PointsAll: return out;  // summed whole, never drawn
    }
    out.dir = fromLocal(local);
    out.radiance = out.pdf > 0.f ? lookupUV(out.uv) : Color(0.f);
    return out;
  }

  // The product strategy's sample once its pixel is drawn (CosineProductView::sample's uv and
  // density, or a ProductDescent's end): placed inside the pixel, turned into a direction and
  // looked up.
  ENVGI_HD EnvSample productSample(Vec2f uv, float pdfUV) const {
    uv = placeInPixel(uv, &pdfUV);
    return placedProductSample(uv, pdfUV, fromLocal(uvToDir(uv)), lookupUV(uv));
  }
  // The same where the placing, the direction and the lookup were done apart (placeInPixel's uv
  // and density, fromLocal(uvToDir(uv)) and lookupUV(uv)), as for a batch of draws.
  ENVGI_HD EnvSample placedProductSample(Vec2f uv, float pdfUV, Vec3f dir, Color radiance) const {
    EnvSample out;
    out.uv = uv;
    out.pdf = solidAnglePdf(pdfUV, uv.y);
    out.dir = dir;
    out.radiance = out.pdf > 0.f ? radiance : Color(0.f);
    return out;
  }

  ENVGI_HD float pdf(EnvStrategy s, Vec3f worldDir, Vec3f normal = Vec3f(0.f, 1.f, 0.f)) const {
    EnvStrategy t = strategyFor(s, normal);
    bool mapped = t != EnvStrategy::Uniform && t != EnvStrategy::Cosine && !isCollapsedMap(t);
    return pdfAt(t, worldDir, mapped ? uvOf(worldDir) : Vec2f(0.f, 0.f), normal);
  }

  // Radiance from world direction d and, through *pdfOut, the density strategy s gives it about
  // `normal`: one mapping to (u, v) serves both, which is what a BSDF-sampled ray that escapes
  // needs (two atan2 calls and a rotation fewer than eval() and pdf() apart).
  ENVGI_HD Color evalWithPdf(EnvStrategy s, Vec3f worldDir, Vec3f normal, float* pdfOut) const {
    return evalWithPdfAt(s, worldDir, uvOf(worldDir), normal, pdfOut);
  }
  // evalWithPdf where worldDir's (u, v) is known.
  ENVGI_HD Color evalWithPdfAt(EnvStrategy s, Vec3f worldDir, Vec2f uv, Vec3f normal, float* pdfOut) const {
    *pdfOut = pdfAtUV(s, worldDir, uv, normal);
    return lookupUV(uv);
  }
  // pdf where worldDir's (u, v) is known.
  ENVGI_HD float pdfAtUV(EnvStrategy s, Vec3f worldDir, Vec2f uv, Vec3f normal) const {
    return pdfAt(strategyFor(s, normal), worldDir, uv, normal);
  }

 private:
  // t is already resolved by strategyFor(); uv is worldDir's (u, v) where t needs it.
  ENVGI_HD float pdfAt(EnvStrategy t, Vec3f worldDir, Vec2f uv, Vec3f normal) const {
    switch (t) {
      case EnvStrategy::Uniform: return uniformSpherePdf();
      case EnvStrategy::Cosine: return cosineHemispherePdf(dot(normalize(worldDir), normal));
      case EnvStrategy::Importance:
      case EnvStrategy::Alias: return importancePdfUV(uv) * pdfInPixel(uv);
      case EnvStrategy::Adaptive: return adaptive.pdf(uv);
      case EnvStrategy::Algorithm1: return solidAnglePdf(paperDist.pdf(uv), uv.y);
      case EnvStrategy::Points:
      case EnvStrategy::PointsAll: return 0.f;  // no direction drawn by BSDF sampling hits a point
      case EnvStrategy::Product:
        return solidAnglePdf(product.pdf(uv, toLocalUnnormalized(normal)) * pdfInPixel(uv), uv.y);
    }
    return 0.f;
  }
};

}  // namespace envgi
