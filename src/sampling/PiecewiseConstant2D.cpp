#include "sampling/PiecewiseConstant2D.h"

#include <tbb/parallel_for.h>

namespace envgi {

PiecewiseConstant2D::PiecewiseConstant2D(const float* func, int cols, int rows) : cols_(cols), rows_(rows) {
  condFunc_.resize(size_t(rows) * cols);
  condCdf_.resize(size_t(rows) * (cols + 1));
  condInt_.resize(rows);
  // Rows are independent; a 4096x2048 map builds in parallel.
  tbb::parallel_for(0, rows, [&](int r) {
    PiecewiseConstant1D::build(func + size_t(r) * cols, cols, condFunc_.data() + size_t(r) * cols,
                               condCdf_.data() + size_t(r) * (cols + 1), &condInt_[r]);
  });
  PiecewiseConstant1D::build(condInt_.data(), rows, margFunc_, margCdf_, margInt_);
}

PiecewiseConstant2DView PiecewiseConstant2D::view() const {
  PiecewiseConstant2DView v;
  v.condFunc = condFunc_.data();
  v.condCdf = condCdf_.data();
  v.condInt = condInt_.data();
  v.marginal = {margFunc_.data(), margCdf_.data(), rows_, margInt_};
  v.cols = cols_;
  v.rows = rows_;
  return v;
}

}  // namespace envgi
