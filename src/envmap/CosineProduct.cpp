#include "envmap/CosineProduct.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace envgi {

namespace {

struct Dir {
  double x, y, z;
};

// The map's convention (EnvironmentMapView::uvToDir), in double for the bounds.
Dir uvDir(double u, double v) {
  double phi = 2.0 * M_PI * u, theta = M_PI * v, st = std::sin(theta);
  return {st * std::sin(phi), std::cos(theta), -st * std::cos(phi)};
}

double angleBetween(const Dir& a, const Dir& b) {
  double d = a.x * b.x + a.y * b.y + a.z * b.z;
  return std::acos(std::clamp(d, -1.0, 1.0));
}

Dir toDir(Vec3f v) { return {v.x, v.y, v.z}; }

// Centre and angular radius of a region sampled on a (k+1) x (k+1) grid of its parameters,
// widened by a margin so that the cap holds the edges between the grid points too.
template <class F>
void boundingCap(F at, Dir centre, double* radius) {
  const int k = 8;
  double r = 0.0;
  for (int j = 0; j <= k; ++j)
    for (int i = 0; i <= k; ++i) r = std::max(r, angleBetween(centre, at(double(i) / k, double(j) / k)));
  *radius = r * 1.05 + 1e-3;
}

}  // namespace

CosineProduct::CosineProduct(const float* w, int width, int height, int cellsX, int cellsY, int bucketsPerSide)
    : width_(width), height_(height), cellsX_(std::min(cellsX, width)), cellsY_(std::min(cellsY, height)),
      buckets_(bucketsPerSide) {
  if (width <= 0 || height <= 0 || cellsX <= 0 || cellsY <= 0 || bucketsPerSide <= 0)
    throw std::runtime_error("cosine product: empty map or grid");
  CosineProductView v;
  v.width = width_;
  v.height = height_;
  v.cellsX = cellsX_;
  v.cellsY = cellsY_;
  const int cells = cellsX_ * cellsY_;
  layout_.reserve(size_t(cellsX_ + 1 + cellsY_ + 1 + width + height));
  for (int cx = 0; cx <= cellsX_; ++cx) layout_.push_back(v.cellX0(cx));
  for (int cy = 0; cy <= cellsY_; ++cy) layout_.push_back(v.cellY0(cy));
  for (int x = 0; x < width; ++x) layout_.push_back(v.cellOfPixel(x, 0));
  for (int y = 0; y < height; ++y) layout_.push_back(v.cellOfPixel(0, y) / cellsX_);

  // Per cell: the cdf of its pixels' weights and their sum; its bounding cap on the sphere.
  // Guides: about one entry per 4 pixels of the largest cell (64 at most) and per 4 cells.
  int maxPixels = (v.cellX0(1) - v.cellX0(0) + 1) * (v.cellY0(1) - v.cellY0(0) + 1);
  cellGuideSize_ = std::min(guideSize(maxPixels, 4), 64);
  bucketGuideSize_ = guideSize(cells, 4);
  cellGuide_.resize(size_t(cells) * (cellGuideSize_ + 1));
  bucketGuide_.resize(size_t(bucketsPerSide) * bucketsPerSide * (bucketGuideSize_ + 1));
  cellCdfStart_.resize(size_t(cells));
  std::vector<float> cellSum(static_cast<size_t>(cells));
  std::vector<Dir> cellCentre(static_cast<size_t>(cells));
  std::vector<double> cellRadius(static_cast<size_t>(cells));
  std::vector<float> f, func;  // one cell's pixel weights, and build()'s copy of them
  for (int cy = 0; cy < cellsY_; ++cy)
    for (int cx = 0; cx < cellsX_; ++cx) {
      int c = cy * cellsX_ + cx;
      int x0 = v.cellX0(cx), x1 = v.cellX0(cx + 1), y0 = v.cellY0(cy), y1 = v.cellY0(cy + 1);
      f.clear();
      double sum = 0.0;
      for (int y = y0; y < y1; ++y)
        for (int x = x0; x < x1; ++x) {
          f.push_back(w[size_t(y) * width + x]);
          sum += f.back();
        }
      cellCdfStart_[size_t(c)] = int(cellCdf_.size());
      cellCdf_.resize(cellCdf_.size() + f.size() + 1);
      func.resize(f.size());
      float integral;
      PiecewiseConstant1D::build(f.data(), int(f.size()), func.data(), cellCdf_.data() + cellCdfStart_[size_t(c)],
                                 &integral);
      cellSum[size_t(c)] = float(sum);
      buildGuide(cellCdf_.data() + cellCdfStart_[size_t(c)], int(f.size()) + 1, cellGuideSize_,
                 cellGuide_.data() + size_t(c) * (cellGuideSize_ + 1));
      double u0 = double(x0) / width, u1 = double(x1) / width, v0 = double(y0) / height, v1 = double(y1) / height;
      auto at = [&](double s, double t) { return uvDir(u0 + s * (u1 - u0), v0 + t * (v1 - v0)); };
      cellCentre[size_t(c)] = at(0.5, 0.5);
      boundingCap(at, cellCentre[size_t(c)], &cellRadius[size_t(c)]);
    }

  // Per bucket of normals: cell power times the largest cosine any of its normals can have
  // with any direction in the cell (zero only where the whole cell is below every normal).
  const int buckets = buckets_ * buckets_;
  func.resize(size_t(cells));  // build()'s copy of a bucket's weights: not kept, pdfUV reads the cdf
  bucketCdf_.resize(size_t(buckets) * (cells + 1));
  bucketInt_.resize(size_t(buckets));
  std::vector<float> weights(static_cast<size_t>(cells));
  for (int by = 0; by < buckets_; ++by)
    for (int bx = 0; bx < buckets_; ++bx) {
      int k = by * buckets_ + bx;
      double s0 = double(bx) / buckets_, t0 = double(by) / buckets_, step = 1.0 / buckets_;
      auto at = [&](double s, double t) {
        return toDir(octahedralDecode(Vec2f(float(s0 + s * step), float(t0 + t * step))));
      };
      Dir n = at(0.5, 0.5);
      double delta;
      boundingCap(at, n, &delta);
      for (int c = 0; c < cells; ++c) {
        double gap = angleBetween(n, cellCentre[size_t(c)]) - cellRadius[size_t(c)] - delta;
        double g = gap <= 0.0 ? 1.0 : (gap < M_PI / 2 ? std::cos(gap) : 0.0);
        weights[size_t(c)] = float(double(cellSum[size_t(c)]) * g);
      }
      PiecewiseConstant1D::build(weights.data(), cells, func.data(),
                                 bucketCdf_.data() + size_t(k) * (cells + 1), &bucketInt_[size_t(k)]);
      buildGuide(bucketCdf_.data() + size_t(k) * (cells + 1), cells + 1, bucketGuideSize_,
                 bucketGuide_.data() + size_t(k) * (bucketGuideSize_ + 1));
    }
}

CosineProductView CosineProduct::view() const {
  CosineProductView v;
  if (buckets_ == 0) return v;
  v.bucketCdf = bucketCdf_.data();
  v.bucketInt = bucketInt_.data();
  v.cellCdf = cellCdf_.data();
  v.cellCdfStart = cellCdfStart_.data();
  v.bucketGuide = bucketGuide_.data();
  v.cellGuide = cellGuide_.data();
  v.cellStartX = layout_.data();
  v.cellStartY = v.cellStartX + cellsX_ + 1;
  v.columnCell = v.cellStartY + cellsY_ + 1;
  v.rowCell = v.columnCell + width_;
  v.bucketGuideSize = bucketGuideSize_;
  v.cellGuideSize = cellGuideSize_;
  v.width = width_;
  v.height = height_;
  v.cellsX = cellsX_;
  v.cellsY = cellsY_;
  v.bucketsPerSide = buckets_;
  return v;
}

size_t CosineProduct::bytes() const {
  return sizeof(float) * (bucketCdf_.size() + bucketInt_.size() + cellCdf_.size()) +
         sizeof(int) * (cellCdfStart_.size() + bucketGuide_.size() + cellGuide_.size() + layout_.size());
}

}  // namespace envgi
