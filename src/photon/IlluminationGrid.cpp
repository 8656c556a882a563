#include "photon/IlluminationGrid.h"

#include <algorithm>
#include <stdexcept>

namespace envgi {

IlluminationGrid::IlluminationGrid(Vec3f lo, Vec3f hi, int nx, int ny, int nz) {
  if (nx < 2 || ny < 2 || nz < 2) throw std::runtime_error("grid: the resolution must be at least 2 a side");
  view_.lo = lo;
  view_.nx = nx;
  view_.ny = ny;
  view_.nz = nz;
  Vec3f ext = hi - lo;
  // A flat scene still gets a grid with some depth.
  float minExt = 1e-3f * std::max({ext.x, ext.y, ext.z, 1e-3f});
  view_.spacing = Vec3f(std::max(ext.x, minExt) / float(nx - 1), std::max(ext.y, minExt) / float(ny - 1),
                        std::max(ext.z, minExt) / float(nz - 1));
  size_t n = pointCount();
  sum_.assign(n, ShL1{});
  sh_.assign(n, ShL1{});
  count_.assign(n, 0);
  back_.assign(n, 0);
  weight_.assign(n, 1.f);
  view_.sh = sh_.data();
  view_.weight = weight_.data();
}

Vec3f IlluminationGrid::point(size_t i) const { return view_.point(i); }

void IlluminationGrid::accumulate(size_t i, const ShL1& s, int n, int backHits) {
  for (int c = 0; c < 4; ++c) sum_[i].c[c] += s.c[c];
  count_[i] += n;
  back_[i] += backHits;
}

void IlluminationGrid::finish() {
  for (size_t i = 0; i < sum_.size(); ++i) {
    float inv = count_[i] > 0 ? 1.f / float(count_[i]) : 0.f;
    for (int c = 0; c < 4; ++c) sh_[i].c[c] = sum_[i].c[c] * inv;
    // A point that meets back faces with a quarter or more of its rays is inside something.
    weight_[i] = count_[i] > 0 && 4 * back_[i] < count_[i] ? 1.f : 0.f;
  }
}

size_t IlluminationGrid::bytes() const {
  return sum_.size() * kBytesPerPoint;
}

}  // namespace envgi
