#include "photon/DirectionalGrid.h"

#include <algorithm>
#include <stdexcept>

namespace envgi {

DirectionalGrid::DirectionalGrid(Vec3f lo, Vec3f hi, int nx, int ny, int nz, std::vector<Vec3f> dirs,
                                 std::vector<float> share)
    : dirs_(std::move(dirs)), share_(std::move(share)) {
  if (nx < 2 || ny < 2 || nz < 2) throw std::runtime_error("grid: the resolution must be at least 2 a side");
  if (dirs_.empty() || dirs_.size() != share_.size()) throw std::runtime_error("grid: no directions");
  view_.lo = lo;
  view_.nx = nx, view_.ny = ny, view_.nz = nz;
  Vec3f ext = hi - lo;
  float minExt = 1e-3f * std::max({ext.x, ext.y, ext.z, 1e-3f});
  view_.spacing = Vec3f(std::max(ext.x, minExt) / float(nx - 1), std::max(ext.y, minExt) / float(ny - 1),
                        std::max(ext.z, minExt) / float(nz - 1));
  view_.m = int(dirs_.size());
  const size_t n = pointCount();
  sum_.assign(n * dirs_.size(), Color(0.f));
  coeff_.assign(n * dirs_.size(), Color(0.f));
  count_.assign(n, 0);
  back_.assign(n, 0);
  weight_.assign(n, 1.f);
  view_.dirs = dirs_.data();
  view_.share = share_.data();
  view_.coeff = coeff_.data();
  view_.weight = weight_.data();
}

void DirectionalGrid::accumulate(size_t i, const Color* sums, int samples, int backHits) {
  const size_t m = dirs_.size();
  for (size_t k = 0; k < m; ++k) sum_[i * m + k] += sums[k];
  count_[i] += samples;
  back_[i] += backHits;
}

void DirectionalGrid::finish() {
  const size_t m = dirs_.size();
  for (size_t i = 0; i < count_.size(); ++i) {
    const float inv = count_[i] > 0 ? 1.f / float(count_[i]) : 0.f;
    for (size_t k = 0; k < m; ++k) coeff_[i * m + k] = sum_[i * m + k] * inv;
    // As the SH grid: a point whose rays meet back faces a quarter of the time is inside.
    weight_[i] = count_[i] > 0 && 4 * back_[i] < count_[i] * int(m) ? 1.f : 0.f;
  }
}

}  // namespace envgi
