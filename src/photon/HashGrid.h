// A hashed uniform grid over points (SPPM's visible points): counting-sorted into flat
// arrays, so the photon pass can query it on the CPU or in a CUDA kernel. No kd-tree.
#pragma once

#include <vector>

#include "core/Vec.h"

namespace envgi {

struct HashGridView {
  const int* bucketStart = nullptr;  // tableSize + 1 offsets into items
  const int* items = nullptr;        // point indices, grouped by bucket
  int tableSize = 0;
  float cellSize = 1.f;

  ENVGI_HD void cellOf(Vec3f p, int* x, int* y, int* z) const {
    *x = int(std::floor(p.x / cellSize));
    *y = int(std::floor(p.y / cellSize));
    *z = int(std::floor(p.z / cellSize));
  }
  ENVGI_HD int bucket(int x, int y, int z) const {
    uint32_t h = (uint32_t(x) * 73856093u) ^ (uint32_t(y) * 19349663u) ^ (uint32_t(z) * 83492791u);
    return int(h % uint32_t(tableSize));
  }

  // Calls visit(index) once for every point stored in the 27 cells around p; callers check
  // the distance (different cells can share a bucket).
  template <class Visit>
  ENVGI_HD void forNeighbours(Vec3f p, Visit&& visit) const {
    if (tableSize == 0) return;
    int cx, cy, cz;
    cellOf(p, &cx, &cy, &cz);
    int seen[27];
    int nSeen = 0;
    for (int dz = -1; dz <= 1; ++dz)
      for (int dy = -1; dy <= 1; ++dy)
        for (int dx = -1; dx <= 1; ++dx) {
          int b = bucket(cx + dx, cy + dy, cz + dz);
          bool dup = false;
          for (int i = 0; i < nSeen; ++i) dup = dup || seen[i] == b;
          if (dup) continue;
          seen[nSeen++] = b;
          for (int i = bucketStart[b]; i < bucketStart[b + 1]; ++i) visit(items[i]);
        }
  }
};

class HashGrid {
 public:
  // Points with valid[i] == false are left out. cellSize must be at least the search radius.
  void build(const std::vector<Vec3f>& points, const std::vector<char>& valid, float cellSize) {
    size_t n = 0;
    for (char v : valid) n += v ? 1 : 0;
    view_.tableSize = int(std::max<size_t>(1, 2 * n));
    view_.cellSize = cellSize;
    start_.assign(size_t(view_.tableSize) + 1, 0);
    items_.assign(n, 0);
    std::vector<int> bucketOf(points.size(), -1);
    for (size_t i = 0; i < points.size(); ++i) {
      if (!valid[i]) continue;
      int x, y, z;
      view_.cellOf(points[i], &x, &y, &z);
      bucketOf[i] = view_.bucket(x, y, z);
      ++start_[size_t(bucketOf[i]) + 1];
    }
    for (size_t b = 0; b < size_t(view_.tableSize); ++b) start_[b + 1] += start_[b];
    std::vector<int> fill(start_.begin(), start_.end() - 1);
    for (size_t i = 0; i < points.size(); ++i)
      if (bucketOf[i] >= 0) items_[size_t(fill[size_t(bucketOf[i])]++)] = int(i);
    view_.bucketStart = start_.data();
    view_.items = items_.data();
  }
  const HashGridView& view() const { return view_; }
  size_t bytes() const { return (start_.size() + items_.size()) * sizeof(int); }

 private:
  HashGridView view_;
  std::vector<int> start_, items_;
};

}  // namespace envgi
