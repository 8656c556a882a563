// Christensen's precomputed photon irradiance (1999) as a lookup that runs on the CPU and in
// CUDA kernels: irradiance points (position, normal, irradiance, and the squared radius of the
// photons it came from) in hashed grids, one a level of radius. Level l holds the points whose
// radius is at most the largest over 2^l (and more than half that), in cells twice that size,
// so the points that can cover a query lie in the 2 x 2 x 2 cells its box of that half-size
// overlaps. One grid sized by the largest radius made a query in a dense region (small radii)
// read every point within three of the sparsest region's radii: 2600 a gather ray in the glass
// teapot, whose radii span 0.07 to 1.
#pragma once

#include <cmath>
#include <vector>

#include "photon/HashGrid.h"

namespace envgi {

// Photons and irradiance points count as on the surface being shaded when their normals are
// this close to its normal (not the far side of a thin wall, not a nearby crease).
inline constexpr float kSameSurfaceCos = 0.9f;

// Levels of radius the cache's grids span: radii below the largest / 2^(levels - 1) share the
// finest level.
inline constexpr int kIrradianceLevels = 6;

struct IrradiancePoint {
  Vec3f p, n;
  Color e;
  float r2;  // squared radius of the photons it was estimated from
};

struct IrradianceCacheView {
  // The points level by level, each level's in its grid's bucket order, so that a bucket's
  // points are read one after another; id is each one's index among the points as given.
  const IrradiancePoint* points = nullptr;
  const int* id = nullptr;
  HashGridView levels[kIrradianceLevels];  // the levels that hold points, coarsest first
  int first[kIrradianceLevels] = {};       // each one's first point in points
  float reach[kIrradianceLevels] = {};     // each one's largest radius (half its cell), a hair over
  int levelCount = 0;

  // Irradiance near p on a surface facing n: that of the nearest point facing the same way
  // whose own estimate covered p, zero where none does (a gather ray that lands where no
  // photons arrived must not borrow a distant surface's light).
  ENVGI_HD Color irradiance(Vec3f p, Vec3f n) const {
    float best = INFINITY;
    int bestId = -1, bestAt = -1;
    for (int l = 0; l < levelCount; ++l)
      levels[l].forBucketsAround(p, reach[l], [&](int begin, int end) {
        for (int j = first[l] + begin; j < first[l] + end; ++j) {
          const IrradiancePoint& ip = points[j];
          float d2 = lengthSq(ip.p - p);
          // Ties go to the lower id, so the answer does not depend on the buckets' order.
          if (d2 <= ip.r2 && (d2 < best || (d2 == best && id[j] < bestId)) && dot(ip.n, n) > kSameSurfaceCos) {
            best = d2;
            bestId = id[j];
            bestAt = j;
          }
        }
      });
    return bestAt >= 0 ? points[bestAt].e : Color(0.f);
  }
};

class IrradianceCache {
 public:
  void build(std::vector<IrradiancePoint> given) {
    float maxR2 = 0.f;
    for (const IrradiancePoint& ip : given) maxR2 = fmaxf(maxR2, ip.r2);
    // Level l's reach: the largest radius over 2^l (exact in floats). A point's level is the
    // finest whose reach's square is at least its r2.
    const float reach0 = std::sqrt(fmaxf(maxR2, 1e-12f));
    std::vector<int> levelOf(given.size());
    for (size_t i = 0; i < given.size(); ++i) {
      int l = 0;
      for (float h = reach0 * 0.5f; l + 1 < kIrradianceLevels && h * h >= given[i].r2; h *= 0.5f) ++l;
      levelOf[i] = l;
    }
    std::vector<Vec3f> pos(given.size());
    for (size_t i = 0; i < given.size(); ++i) pos[i] = given[i].p;
    grids_.clear();
    points_.clear();
    ids_.clear();
    view_ = IrradianceCacheView();
    for (int l = 0; l < kIrradianceLevels; ++l) {
      std::vector<char> here(given.size());
      bool any = false;
      for (size_t i = 0; i < given.size(); ++i) any |= (here[i] = levelOf[i] == l) != 0;
      if (!any) continue;
      const float h = std::ldexp(reach0, -l);
      HashGrid grid;
      grid.build(pos, here, 2.f * h);
      const int g = int(grids_.size());
      // A hair over the reach: r2 <= h * h, rounded, may still put r a few ulps past h.
      view_.reach[g] = h * (1.f + 1e-5f);
      view_.first[g] = int(points_.size());
      const HashGridView& gv = grid.view();
      for (int j = 0; j < gv.bucketStart[gv.tableSize]; ++j) {
        points_.push_back(given[size_t(gv.items[j])]);
        ids_.push_back(gv.items[j]);
      }
      grids_.push_back(std::move(grid));
    }
    for (size_t g = 0; g < grids_.size(); ++g) view_.levels[g] = grids_[g].view();
    view_.levelCount = int(grids_.size());
    view_.points = points_.data();
    view_.id = ids_.data();
  }
  const IrradianceCacheView& view() const { return view_; }
  // The points in the view's order, and their ids (indices among the points given to build).
  const std::vector<IrradiancePoint>& points() const { return points_; }
  const std::vector<int>& ids() const { return ids_; }
  size_t bytes() const {
    size_t b = points_.size() * (sizeof(IrradiancePoint) + sizeof(int));
    for (const HashGrid& g : grids_) b += g.bytes();
    return b;
  }

 private:
  std::vector<IrradiancePoint> points_;
  std::vector<int> ids_;
  std::vector<HashGrid> grids_;  // HashGrid moves keep their views valid
  IrradianceCacheView view_;
};

}  // namespace envgi
