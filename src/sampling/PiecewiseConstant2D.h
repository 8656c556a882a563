// Piecewise-constant density on [0,1]^2: a marginal over rows and one conditional per row,
// stored flat so that a kernel can read it through plain pointers (the paper's Algorithm 1).
#pragma once

#include "sampling/PiecewiseConstant1D.h"
#include "core/Vec.h"

namespace envgi {

struct PiecewiseConstant2DView {
  const float* condFunc = nullptr;  // rows * cols
  const float* condCdf = nullptr;   // rows * (cols + 1)
  const float* condInt = nullptr;   // rows
  PiecewiseConstant1DView marginal;  // over rows, func = condInt
  int cols = 0, rows = 0;

  ENVGI_HD PiecewiseConstant1DView conditional(int row) const {
    return {condFunc + size_t(row) * cols, condCdf + size_t(row) * (cols + 1), cols, condInt[row]};
  }
  ENVGI_HD float integral() const { return marginal.funcInt; }

  // Returns a point in [0,1)^2 (x across columns, y down rows) and its density.
  ENVGI_HD Vec2f sample(Vec2f u, float* pdfOut) const {
    float pdfY, pdfX;
    int row;
    float y = marginal.sample(u.y, &pdfY, &row);
    float x = conditional(row).sample(u.x, &pdfX, nullptr);
    if (pdfOut) *pdfOut = pdfX * pdfY;
    return {x, y};
  }
  ENVGI_HD float pdf(Vec2f p) const {
    int c = clampi(int(p.x * cols), 0, cols - 1);
    int r = clampi(int(p.y * rows), 0, rows - 1);
    if (marginal.funcInt <= 0.f) return 1.f;
    return condFunc[size_t(r) * cols + c] / marginal.funcInt;
  }
  ENVGI_HD Vec2f invert(Vec2f p) const {
    int r = clampi(int(p.y * rows), 0, rows - 1);
    return {conditional(r).invert(p.x), marginal.invert(p.y)};
  }
};

class PiecewiseConstant2D {
 public:
  PiecewiseConstant2D() = default;
  // func is row-major, rows * cols non-negative values.
  PiecewiseConstant2D(const float* func, int cols, int rows);

  PiecewiseConstant2DView view() const;
  float integral() const { return margInt_; }
  size_t bytes() const {
    return sizeof(float) * (condFunc_.size() + condCdf_.size() + condInt_.size() + margFunc_.size() + margCdf_.size());
  }

 private:
  std::vector<float> condFunc_, condCdf_, condInt_, margFunc_, margCdf_;
  float margInt_ = 0.f;
  int cols_ = 0, rows_ = 0;
};

}  // namespace envgi
