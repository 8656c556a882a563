// Christensen's precomputed photon irradiance (1999) as a lookup that runs on the CPU and in
// CUDA kernels: irradiance points (position, normal, irradiance, and the squared radius of the
// photons it came from) in a hashed grid whose cell is the largest radius, so every point that
// can cover a query lies in the 27 cells around it.
#pragma once

#include <vector>

#include "photon/HashGrid.h"

namespace envgi {

// Photons and irradiance points count as on the surface being shaded when their normals are
// this close to its normal (not the far side of a thin wall, not a nearby crease).
inline constexpr float kSameSurfaceCos = 0.9f;

struct IrradiancePoint {
  Vec3f p, n;
  Color e;
  float r2;  // squared radius of the photons it was estimated from
};

struct IrradianceCacheView {
  const IrradiancePoint* points = nullptr;
  HashGridView grid;

  // Irradiance near p on a surface facing n: that of the nearest point facing the same way
  // whose own estimate covered p, zero where none does (a gather ray that lands where no
  // photons arrived must not borrow a distant surface's light).
  ENVGI_HD Color irradiance(Vec3f p, Vec3f n) const {
    float best = INFINITY;
    int bestIdx = -1;
    grid.forNeighbours(p, [&](int i) {
      const IrradiancePoint& ip = points[i];
      float d2 = lengthSq(ip.p - p);
      // Ties go to the lower index, so the answer does not depend on the buckets' order.
      if (d2 <= ip.r2 && (d2 < best || (d2 == best && i < bestIdx)) && dot(ip.n, n) > kSameSurfaceCos) {
        best = d2;
        bestIdx = i;
      }
    });
    return bestIdx >= 0 ? points[bestIdx].e : Color(0.f);
  }
};

class IrradianceCache {
 public:
  void build(std::vector<IrradiancePoint> points) {
    points_ = std::move(points);
    std::vector<Vec3f> pos(points_.size());
    std::vector<char> valid(points_.size(), 1);
    float maxR2 = 0.f;
    for (size_t i = 0; i < points_.size(); ++i) {
      pos[i] = points_[i].p;
      maxR2 = fmaxf(maxR2, points_[i].r2);
    }
    grid_.build(pos, valid, std::sqrt(fmaxf(maxR2, 1e-12f)));
    view_.points = points_.data();
    view_.grid = grid_.view();
  }
  const IrradianceCacheView& view() const { return view_; }
  const std::vector<IrradiancePoint>& points() const { return points_; }
  size_t bytes() const { return points_.size() * sizeof(IrradiancePoint) + grid_.bytes(); }

 private:
  std::vector<IrradiancePoint> points_;
  HashGrid grid_;
  IrradianceCacheView view_;
};

}  // namespace envgi
