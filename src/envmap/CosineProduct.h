// The map's density times a bound on the clamped cosine about a surface normal: the `product`
// strategy. Next-event estimation with Algorithm 1's density sends about half its samples
// below the surface (where a reflecting BSDF is zero); this one samples in proportion to
// L(w) g(n, w), with g >= max(0, n.w) over each cell of the map and each bucket of normals,
// so that every direction the BSDF can use keeps a non-zero density.
//
// Two levels: normals fall into an octahedral grid of buckets, and each bucket holds a 1D
// distribution over coarse cells of the map (cell power times g); within a cell a pixel is
// drawn by the map's own per-pixel weights (luminance x sin theta, the same as Algorithm 1's),
// and a point inside the pixel uniformly.
#pragma once

#include <vector>

#include "core/Vec.h"
#include "sampling/PiecewiseConstant1D.h"

namespace envgi {

// The octahedron's lower half folded over its upper one (its own inverse).
ENVGI_INLINE Vec2f octahedralFold(float px, float py) {
  return {(1.f - std::fabs(py)) * (px >= 0.f ? 1.f : -1.f), (1.f - std::fabs(px)) * (py >= 0.f ? 1.f : -1.f)};
}

// Octahedral mapping of a unit vector to [0,1)^2 (Meyer et al. 2010), for bucketing normals.
ENVGI_INLINE Vec2f octahedralEncode(Vec3f n) {
  float s = std::fabs(n.x) + std::fabs(n.y) + std::fabs(n.z);
  Vec2f p(n.x / s, n.y / s);
  if (n.z < 0.f) p = octahedralFold(p.x, p.y);
  return {p.x * 0.5f + 0.5f, p.y * 0.5f + 0.5f};
}

ENVGI_INLINE Vec3f octahedralDecode(Vec2f uv) {
  Vec2f p(uv.x * 2.f - 1.f, uv.y * 2.f - 1.f);
  float z = 1.f - std::fabs(p.x) - std::fabs(p.y);
  if (z < 0.f) p = octahedralFold(p.x, p.y);
  return normalize(Vec3f(p.x, p.y, z));
}

// (p + r) / n for r in [0, 1], as a coordinate that pdf() maps back to pixel p (int(f n) == p):
// near r = 1 the sum, the division or pdf()'s product may round onto the next pixel's edge,
// which would give a draw the neighbour's density.
// Settle false: without the steps onto pixel p (EnvironmentMapView::warpInPixelIn).
template <bool Settle = true>
ENVGI_INLINE float insidePixel(int p, float r, int n) {
  float f = (float(p) + (r < kOneMinusEpsilon ? r : kOneMinusEpsilon)) / float(n);
  f = f < kOneMinusEpsilon ? f : kOneMinusEpsilon;
  if (Settle) {
    while (int(f * float(n)) > p) f = nextafterf(f, 0.f);
    while (int(f * float(n)) < p) f = nextafterf(f, 1.f);
  }
  return f;
}

// A draw of sample() taken one level of its dependent loads at a time (descend0 to
// descendToPixel, then descentEnd). Each level's address comes from the one before, so a batch
// of draws that asks every draw for a level before reading any of them overlaps the cache misses
// that sample() takes in a row. Host only: it prefetches.
struct ProductDescent {
  int k = -1, c = -1;  // the bucket; the cell, once known
  int lo = 0, hi = 0;  // the guide's bracket at the level being asked for
  int j = -1;          // the pixel inside the cell, once known
  Vec2f u;
  Vec3f nLocal;
};

struct CosineProductView {
  const float* bucketCdf = nullptr;   // buckets x (cells + 1), over cell power times the cosine bound
  const float* bucketInt = nullptr;   // buckets: the mean cell power times the bound (0: no light)
  const float* cellCdf = nullptr;     // each cell's pixels (row-major inside the cell): pixels + 1 values
  const int* cellCdfStart = nullptr;  // cells: where a cell's cdf begins in cellCdf
  // Guide tables (findIntervalGuided) over bucketCdf, buckets x (bucketGuideSize + 1), and over
  // each cell's cdf, cells x (cellGuideSize + 1): the same draws as binary search, fewer loads.
  const int* bucketGuide = nullptr;
  const int* cellGuide = nullptr;
  int bucketGuideSize = 0, cellGuideSize = 0;
  // cellX0 and cellY0 of every cell column and row (cellsX + 1 and cellsY + 1 entries), and
  // the cell column of every pixel column and the cell row of every pixel row: the per-sample
  // path reads them instead of making 64-bit divisions.
  const int* cellStartX = nullptr;
  const int* cellStartY = nullptr;
  const int* columnCell = nullptr;
  const int* rowCell = nullptr;
  int width = 0, height = 0;          // the map's pixels
  int cellsX = 0, cellsY = 0;
  int bucketsPerSide = 0;             // buckets = bucketsPerSide^2

  ENVGI_HD bool valid() const { return bucketsPerSide > 0; }
  ENVGI_HD int cells() const { return cellsX * cellsY; }
  // nLocal of any length: the octahedral map divides by the sum of its components.
  ENVGI_HD int bucket(Vec3f nLocal) const {
    Vec2f o = octahedralEncode(nLocal);
    int bx = clampi(int(o.x * float(bucketsPerSide)), 0, bucketsPerSide - 1);
    int by = clampi(int(o.y * float(bucketsPerSide)), 0, bucketsPerSide - 1);
    return by * bucketsPerSide + bx;
  }
  // Cell i spans pixels [i W / cellsX, (i + 1) W / cellsX) across, likewise down.
  ENVGI_HD int cellX0(int cx) const { return int((long long)cx * width / cellsX); }
  ENVGI_HD int cellY0(int cy) const { return int((long long)cy * height / cellsY); }
  ENVGI_HD int cellOfPixel(int px, int py) const {
    int cx = int(((long long)(px + 1) * cellsX - 1) / width);
    int cy = int(((long long)(py + 1) * cellsY - 1) / height);
    return cy * cellsX + cx;
  }

  // Density in (u, v) of pixel j (row-major inside cell c) for a normal in bucket k: the chance
  // that the two searches pick it, read off the very cdfs they search (so sample() and pdf()
  // agree to the bit, and a pixel too faint to own a float step of its cdf has no density, as
  // it is never drawn), times the pixel count, since a pixel spans 1 / (width height) of (u, v).
  ENVGI_HD float pdfUV(int k, int c, int j) const {
    if (!(bucketInt[k] > 0.f)) return 0.f;
    const float* cdf = bucketCdf + size_t(k) * (cells() + 1);
    const float* pc = cellCdf + cellCdfStart[c];
    return densityOfSteps(cdf[c + 1] - cdf[c], pc[j + 1] - pc[j]);
  }
  // The one expression sample() and pdfUV() share, so that they cannot drift apart.
  ENVGI_HD float densityOfSteps(float cellStep, float pixelStep) const {
    return cellStep * pixelStep * float(width) * float(height);
  }

  // Draws (u, v) for a normal in the map's frame; false where the bucket sees no light.
  ENVGI_HD bool sample(Vec2f u, Vec3f nLocal, Vec2f* uv, float* pdfOut) const {
    int k = bucket(nLocal), n = cells();
    if (!(bucketInt[k] > 0.f)) return false;
    const float* cdf = bucketCdf + size_t(k) * (n + 1);
    int c = findIntervalGuided(cdf, u.x, bucketGuide + size_t(k) * (bucketGuideSize + 1), bucketGuideSize);
    const float* pc = cellCdf + cellCdfStart[c];
    int j = findIntervalGuided(pc, u.y, cellGuide + size_t(c) * (cellGuideSize + 1), cellGuideSize);
    return drawIn(u, k, c, j, uv, pdfOut);
  }
  // sample()'s end, once its searches found cell c (in bucket k's cdf) and pixel j of the cell.
  ENVGI_HD bool drawIn(Vec2f u, int k, int c, int j, Vec2f* uv, float* pdfOut) const {
    const float* cdf = bucketCdf + size_t(k) * (cells() + 1);
    float w1 = cdf[c + 1] - cdf[c];
    float r1 = w1 > 0.f ? (u.x - cdf[c]) / w1 : 0.5f;
    int cy = c / cellsX, cx = c - cy * cellsX;
    int x0 = cellStartX[cx], x1 = cellStartX[cx + 1], y0 = cellStartY[cy];
    int cw = x1 - x0;
    const float* pc = cellCdf + cellCdfStart[c];
    float w2 = pc[j + 1] - pc[j];
    float r2 = w2 > 0.f ? (u.y - pc[j]) / w2 : 0.5f;
    int jy = j / cw, px = x0 + (j - jy * cw), py = y0 + jy;
    *uv = {insidePixel(px, r1, width), insidePixel(py, r2, height)};
    *pdfOut = densityOfSteps(w1, w2);  // pdfUV(k, c, j), from the values at hand
    return *pdfOut > 0.f;
  }

  // The levels of sample(u, nLocal)'s loads, asked for in order: level 0 the bucket's guide
  // entry, 1 its cdf bracket, 2 the cell's guide entry, 3 the cell's cdf bracket; then the pixel
  // sample() draws (false where it draws none), and descentEnd ends the draw as sample() does,
  // from the loads the levels made.
  void descend0(Vec2f u, Vec3f nLocal, ProductDescent* a) const {
    a->u = u;
    a->nLocal = nLocal;
    a->k = bucket(nLocal);
    if (!(bucketInt[a->k] > 0.f)) { a->k = -1; return; }
    prefetchLine(bucketGuide + size_t(a->k) * (bucketGuideSize + 1) + guideSlot(u.x, bucketGuideSize));
  }
  void descend1(ProductDescent* a) const {
    if (a->k < 0) return;
    const int* g = bucketGuide + size_t(a->k) * (bucketGuideSize + 1) + guideSlot(a->u.x, bucketGuideSize);
    const float* cdf = bucketCdf + size_t(a->k) * (cells() + 1);
    a->lo = g[0], a->hi = g[1];
    prefetchLine(cdf + a->lo);
    prefetchLine(cdf + a->hi);
  }
  void descend2(ProductDescent* a) const {
    if (a->k < 0) return;
    const float* cdf = bucketCdf + size_t(a->k) * (cells() + 1);
    a->c = findIntervalBetweenNoBranch(cdf, a->lo, a->hi, a->u.x);
    prefetchLine(cellGuide + size_t(a->c) * (cellGuideSize + 1) + guideSlot(a->u.y, cellGuideSize));
    prefetchLine(cellCdfStart + a->c);
  }
  void descend3(ProductDescent* a) const {
    if (a->k < 0) return;
    const int* g = cellGuide + size_t(a->c) * (cellGuideSize + 1) + guideSlot(a->u.y, cellGuideSize);
    const float* pc = cellCdf + cellCdfStart[a->c];
    a->lo = g[0], a->hi = g[1];
    prefetchLine(pc + a->lo);
    prefetchLine(pc + a->hi);
  }
  bool descendToPixel(ProductDescent* a, int* px, int* py) const {
    if (a->k < 0) return false;
    const float* pc = cellCdf + cellCdfStart[a->c];
    const int j = a->j = findIntervalBetweenNoBranch(pc, a->lo, a->hi, a->u.y);
    int cy = a->c / cellsX, cx = a->c - cy * cellsX;
    int x0 = cellStartX[cx], cw = cellStartX[cx + 1] - x0;
    int jy = j / cw;
    *px = x0 + (j - jy * cw), *py = cellStartY[cy] + jy;
    return true;
  }
  // sample()'s answer for the descent's u and nLocal: the same uv and density to the bit.
  bool descentEnd(const ProductDescent& a, Vec2f* uv, float* pdfOut) const {
    return a.k >= 0 && drawIn(a.u, a.k, a.c, a.j, uv, pdfOut);
  }

  // Where pdf() reads for (uv, nLocal): the bucket, the cell and the pixel inside the cell.
  struct Step {
    int k, c, j;
  };
  ENVGI_HD Step stepAt(Vec2f uv, Vec3f nLocal) const {
    int px = clampi(int(uv.x * float(width)), 0, width - 1), py = clampi(int(uv.y * float(height)), 0, height - 1);
    int cx = columnCell[px], cy = rowCell[py];
    int x0 = cellStartX[cx], cw = cellStartX[cx + 1] - x0;
    return {bucket(nLocal), cy * cellsX + cx, (py - cellStartY[cy]) * cw + (px - x0)};
  }
  ENVGI_HD float pdf(Vec2f uv, Vec3f nLocal) const {
    const Step s = stepAt(uv, nLocal);
    return pdfUV(s.k, s.c, s.j);
  }
  // The two cdf entries pdf(uv, nLocal) reads first, prefetched (host only).
  void prefetchPdf(Vec2f uv, Vec3f nLocal) const {
    const Step s = stepAt(uv, nLocal);
    prefetchLine(bucketCdf + size_t(s.k) * (cells() + 1) + s.c);
    prefetchLine(cellCdf + cellCdfStart[s.c] + s.j);
  }
};

class CosineProduct {
 public:
  CosineProduct() = default;
  // pixelWeights: width x height, the map's sampling weights (luminance x sin theta).
  CosineProduct(const float* pixelWeights, int width, int height, int cellsX = 64, int cellsY = 32,
                int bucketsPerSide = 16);

  CosineProductView view() const;
  size_t bytes() const;

 private:
  std::vector<float> bucketCdf_, bucketInt_, cellCdf_;
  std::vector<int> cellCdfStart_, bucketGuide_, cellGuide_;
  std::vector<int> layout_;  // cellStartX, cellStartY, columnCell, rowCell, one after the other
  int width_ = 0, height_ = 0, cellsX_ = 0, cellsY_ = 0, buckets_ = 0, bucketGuideSize_ = 0, cellGuideSize_ = 0;
};

}  // namespace envgi
