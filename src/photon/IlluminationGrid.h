// The paper's grid of illumination coefficients (Section 3, its GPU steps): incident indirect
// radiance at the points of a regular n_x x n_y x n_z grid over the scene, stored as L1
// spherical harmonics (4 RGB coefficients a point), read per pixel by trilinear interpolation
// and turned into irradiance for the shading normal (Ramamoorthi and Hanrahan 2001: the
// clamped cosine's SH weights are pi and 2 pi / 3). L1 holds a hemisphere of uniform light
// exactly, so a point beside a wall keeps which side its light comes from.
#pragma once

#include <vector>

#include "core/Vec.h"
#include "photon/GridCorners.h"

namespace envgi {

struct ShL1 {
  Color c[4];  // Y00, Y1-1 (y), Y10 (z), Y11 (x)
};

// The real SH basis up to l = 1 at unit direction d.
ENVGI_INLINE void shL1Basis(Vec3f d, float y[4]) {
  y[0] = 0.282094792f;
  y[1] = 0.488602512f * d.y;
  y[2] = 0.488602512f * d.z;
  y[3] = 0.488602512f * d.x;
}

// Irradiance for normal n from the SH of incident radiance, clamped at zero (L1 rings).
ENVGI_INLINE Color shL1Irradiance(const ShL1& s, Vec3f n) {
  float y[4];
  shL1Basis(n, y);
  const float a0 = kPi, a1 = 2.f * kPi / 3.f;
  Color e = s.c[0] * (a0 * y[0]) + (s.c[1] * y[1] + s.c[2] * y[2] + s.c[3] * y[3]) * a1;
  return Color(fmaxf(e.x, 0.f), fmaxf(e.y, 0.f), fmaxf(e.z, 0.f));
}

struct IlluminationGridView {
  Vec3f lo;             // the grid's first point
  Vec3f spacing;        // between neighbouring points
  int nx = 0, ny = 0, nz = 0;
  const ShL1* sh = nullptr;       // per point, incident radiance
  const float* weight = nullptr;  // per point: 1 where it sees the scene from outside, 0 inside
                                  // an object or a wall (its light would leak through)

  ENVGI_HD Vec3f point(int i, int j, int k) const {
    return lo + Vec3f(spacing.x * float(i), spacing.y * float(j), spacing.z * float(k));
  }
  ENVGI_HD int index(int i, int j, int k) const { return (k * ny + j) * nx + i; }
  // Point number i, x fastest.
  ENVGI_HD Vec3f point(size_t i) const {
    return point(int(i % size_t(nx)), int(i / size_t(nx) % size_t(ny)), int(i / (size_t(nx) * size_t(ny))));
  }

  // Irradiance at p for normal n: the 8 surrounding points' SH, weighted by gridCorners.
  ENVGI_HD Color irradiance(Vec3f p, Vec3f n) const {
    const GridCorners c = gridCorners(lo, spacing, nx, ny, nz, weight, p, n);
    Color sum(0.f);
    for (int k = 0; k < 8; ++k)
      if (c.weight[k] > 0.f) sum += shL1Irradiance(sh[c.index[k]], n) * c.weight[k];
    return sum;
  }
};

// The grid on the host: running sums of gather rays per point, averaged on request.
class IlluminationGrid {
 public:
  IlluminationGrid() = default;  // no points
  // A grid of the given resolution (at least 2 a side) spanning [lo, hi].
  IlluminationGrid(Vec3f lo, Vec3f hi, int nx, int ny, int nz);
  size_t pointCount() const { return size_t(view_.nx) * view_.ny * view_.nz; }
  Vec3f point(size_t i) const;
  // Adds n gather rays' radiance projected on SH (already summed) to point i; backHits of them
  // met a surface from behind. Thread-safe for distinct i.
  void accumulate(size_t i, const ShL1& sum, int n, int backHits);
  // Averages the sums into the coefficients kernels read.
  void finish();
  const IlluminationGridView& view() const { return view_; }
  int raysPerPoint() const { return count_.empty() ? 0 : count_[0]; }
  size_t bytes() const;
  // What each point holds: two sets of coefficients (sums and averages), its ray and back-face
  // counts, its weight.
  static constexpr size_t kBytesPerPoint = 2 * sizeof(ShL1) + 2 * sizeof(int) + sizeof(float);

 private:
  std::vector<ShL1> sum_, sh_;
  std::vector<int> count_, back_;
  std::vector<float> weight_;
  IlluminationGridView view_;
};

}  // namespace envgi
