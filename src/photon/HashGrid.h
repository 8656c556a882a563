// A hashed uniform grid over points (SPPM's visible points): points sorted by bucket into flat
// arrays, so the photon pass can query it on the CPU or in a CUDA kernel. No kd-tree. The CPU
// sorts by counting; a GPU sorts the same keys with CUB's (stable) radix sort and finds the
// bucket starts with hashGridBucketStarts, which gives the same arrays.
#pragma once

#include <vector>

#include "core/Vec.h"

namespace envgi {

// Buckets for n points: twice as many, so few cells share one.
ENVGI_INLINE int hashGridTableSize(size_t n) { return int(n > 0 ? 2 * n : 1); }

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

  // The bucket a point goes into; tableSize (past every bucket) for a point left out.
  ENVGI_HD int key(Vec3f p, bool valid) const {
    if (!valid) return tableSize;
    int x, y, z;
    cellOf(p, &x, &y, &z);
    return bucket(x, y, z);
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

  // Calls visit(begin, end) for the bucket of each cell that the box p +- h overlaps: two cells
  // a side where h is at most half a cell (three at most in any case), each bucket's points at
  // items[begin, end). A bucket comes twice where two of those cells share it; callers that
  // keep a minimum do not mind.
  template <class VisitRange>
  ENVGI_HD void forBucketsAround(Vec3f p, float h, VisitRange&& visit) const {
    if (tableSize == 0) return;
    // Widened by a few ulps of p's largest coordinate: rounding in p +- h and in the division
    // by the cell can then add a cell at the box's edge, never drop one.
    const float m = h + 4e-7f * fmaxf(std::fabs(p.x), fmaxf(std::fabs(p.y), std::fabs(p.z)));
    int x0, y0, z0, x1, y1, z1;
    cellOf(p - Vec3f(m), &x0, &y0, &z0);
    cellOf(p + Vec3f(m), &x1, &y1, &z1);
    // Unsigned spans, capped, so that a far or non-finite p cannot make a long loop.
    auto span = [](int a, int b) { return unsigned(b) - unsigned(a) > 2u ? 2 : int(unsigned(b) - unsigned(a)); };
    const int nx = span(x0, x1), ny = span(y0, y1), nz = span(z0, z1);
    for (int dz = 0; dz <= nz; ++dz)
      for (int dy = 0; dy <= ny; ++dy)
        for (int dx = 0; dx <= nx; ++dx) {
          int b = bucket(x0 + dx, y0 + dy, z0 + dz);
          visit(bucketStart[b], bucketStart[b + 1]);
        }
  }
};

// One thread's share of finding bucket starts from keys sorted ascending (n of them, keys in
// [0, tableSize]): thread i, for i in [0, n], writes start[b] = i for every bucket b whose
// points begin at sorted position i, so start[tableSize] is the number of points kept.
ENVGI_INLINE void hashGridBucketStarts(const int* sortedKeys, int n, int tableSize, int i, int* start) {
  int prev = i > 0 ? sortedKeys[i - 1] : -1;
  int cur = i < n ? sortedKeys[i] : tableSize;
  for (int b = prev + 1; b <= cur && b <= tableSize; ++b) start[b] = i;
}

class HashGrid {
 public:
  // The view points into this object's arrays: moving keeps them valid, copying would not.
  HashGrid() = default;
  HashGrid(const HashGrid&) = delete;
  HashGrid& operator=(const HashGrid&) = delete;
  HashGrid(HashGrid&&) noexcept = default;
  HashGrid& operator=(HashGrid&&) noexcept = default;

  // Points with valid[i] == false are left out. cellSize must be at least the search radius.
  void build(const std::vector<Vec3f>& points, const std::vector<char>& valid, float cellSize) {
    size_t n = 0;
    for (char v : valid) n += v ? 1 : 0;
    view_.tableSize = hashGridTableSize(n);
    view_.cellSize = cellSize;
    start_.assign(size_t(view_.tableSize) + 1, 0);
    items_.assign(n, 0);
    std::vector<int> keyOf(points.size());
    for (size_t i = 0; i < points.size(); ++i) {
      keyOf[i] = view_.key(points[i], valid[i] != 0);
      if (keyOf[i] < view_.tableSize) ++start_[size_t(keyOf[i]) + 1];
    }
    for (size_t b = 0; b < size_t(view_.tableSize); ++b) start_[b + 1] += start_[b];
    std::vector<int> fill(start_.begin(), start_.end() - 1);
    for (size_t i = 0; i < points.size(); ++i)
      if (keyOf[i] < view_.tableSize) items_[size_t(fill[size_t(keyOf[i])]++)] = int(i);
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
