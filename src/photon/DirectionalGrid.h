// The paper's grid (Section 3, GPU steps 1-3): at each point of an n_x x n_y x n_z grid, the
// indirect radiance arriving along each of M directions drawn from the collapsed map, times that
// direction's share of the sphere (its Delta Phi_p), kept as M RGB coefficients a point (the
// paper's M 3D textures). A shading point interpolates them trilinearly and applies its own
// BSDF per direction, so glossy surfaces reflect the grid's light, not just its irradiance.
#pragma once

#include <vector>

#include "core/Vec.h"
#include "photon/GridCorners.h"

namespace envgi {

struct DirectionalGridView {
  Vec3f lo, spacing;
  int nx = 0, ny = 0, nz = 0;
  int m = 0;                      // directions
  const Vec3f* dirs = nullptr;    // world space, towards where the light comes from
  const float* share = nullptr;   // each direction's solid angle (sums to about 4 pi)
  const Color* coeff = nullptr;   // m a point: radiance along dirs[k] times share[k]
  const float* weight = nullptr;  // per point: 1 where it sees the scene from outside, 0 inside

  ENVGI_HD Vec3f point(size_t i) const {
    const int a = int(i % size_t(nx)), b = int(i / size_t(nx) % size_t(ny)), c = int(i / (size_t(nx) * size_t(ny)));
    return lo + Vec3f(spacing.x * float(a), spacing.y * float(b), spacing.z * float(c));
  }
  ENVGI_HD GridCorners corners(Vec3f p, Vec3f n) const { return gridCorners(lo, spacing, nx, ny, nz, weight, p, n); }
  // Coefficient k interpolated over the corners.
  ENVGI_HD Color at(const GridCorners& c, int k) const {
    Color s(0.f);
    for (int j = 0; j < 8; ++j)
      if (c.weight[j] > 0.f) s += coeff[size_t(c.index[j]) * size_t(m) + size_t(k)] * c.weight[j];
    return s;
  }
};

// The grid on the host: running sums of each direction's samples per point, averaged on request.
class DirectionalGrid {
 public:
  DirectionalGrid() = default;
  // A grid of nx x ny x nz points spanning [lo, hi], for the given directions and their shares.
  DirectionalGrid(Vec3f lo, Vec3f hi, int nx, int ny, int nz, std::vector<Vec3f> dirs, std::vector<float> share);
  size_t pointCount() const { return size_t(view_.nx) * view_.ny * view_.nz; }
  int directions() const { return view_.m; }
  // Adds `samples` samples of every direction at point i (sums: m colours, radiance x share,
  // summed over the samples); backHits of the rays met a surface from behind. Thread-safe for
  // distinct i.
  void accumulate(size_t i, const Color* sums, int samples, int backHits);
  void finish();
  const DirectionalGridView& view() const { return view_; }
  int samplesPerDirection() const { return count_.empty() ? 0 : count_[0]; }
  size_t bytes() const { return pointCount() * bytesPerPoint(view_.m); }
  // Two sets of m coefficients (sums and averages), the counts, the weight.
  static size_t bytesPerPoint(int m) { return 2 * size_t(m) * sizeof(Color) + 2 * sizeof(int) + sizeof(float); }

 private:
  std::vector<Vec3f> dirs_;
  std::vector<float> share_;
  std::vector<Color> sum_, coeff_;
  std::vector<int> count_, back_;
  std::vector<float> weight_;
  DirectionalGridView view_;
};

}  // namespace envgi
