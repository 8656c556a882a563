// A triangle cut into n^2 equal cells by n - 1 lines parallel to each side: the lattice of
// barycentric coordinates (b1, b2) times n. A textured area light draws a cell by the texture
// over it, then a point uniformly inside; a point's cell, found in O(1) from its barycentrics,
// gives back its density. Cells are numbered in rows along b2: row r holds 2 (n - r) - 1 cells,
// alternately pointing up (vertices (i, r), (i + 1, r), (i, r + 1)) and down ((i + 1, r),
// (i, r + 1), (i + 1, r + 1)), and starts at r (2n - r).
#pragma once

#include <cmath>

#include "core/Vec.h"
#include "sampling/Warp.h"

namespace envgi {

// The cell of barycentrics b = (b1, b2) (float error near an edge puts it in a neighbour).
ENVGI_INLINE int triangleCellOf(Vec2f b, int n) {
  const float a = fminf(fmaxf(b.x, 0.f), 1.f) * float(n), c = fminf(fmaxf(b.y, 0.f), 1.f) * float(n);
  int r = int(c), i = int(a);
  r = r < 0 ? 0 : (r > n - 1 ? n - 1 : r);
  i = i < 0 ? 0 : (i > n - 1 - r ? n - 1 - r : i);
  int k = 2 * i + ((a - float(i)) + (c - float(r)) >= 1.f ? 1 : 0);
  if (k > 2 * (n - r) - 2) k = 2 * (n - r) - 2;
  return r * (2 * n - r) + k;
}

// Row r and place k of cell `cell`: the largest r with r (2n - r) <= cell.
ENVGI_INLINE void triangleCellRow(int cell, int n, int* r, int* k) {
  int row = int(float(n) - std::sqrt(fmaxf(float(n) * float(n) - float(cell), 0.f)));
  row = row < 0 ? 0 : (row > n - 1 ? n - 1 : row);
  while (row > 0 && row * (2 * n - row) > cell) --row;
  while (row < n - 1 && (row + 1) * (2 * n - row - 1) <= cell) ++row;
  *r = row;
  *k = cell - row * (2 * n - row);
}

// Barycentrics (b1, b2) of a point of cell `cell`, uniform over it for uniform u.
ENVGI_INLINE Vec2f sampleTriangleCell(int cell, int n, Vec2f u) {
  int r, k;
  triangleCellRow(cell, n, &r, &k);
  const Vec2f st = sampleUniformTriangle(u);
  const float i = float(k >> 1);
  const float a = (k & 1) ? i + 1.f - st.x : i + st.x, c = (k & 1) ? float(r) + 1.f - st.y : float(r) + st.y;
  return {a / float(n), c / float(n)};
}

// Corner j (0, 1, 2) of cell `cell`, as barycentrics.
ENVGI_INLINE Vec2f triangleCellCorner(int cell, int n, int j) {
  int r, k;
  triangleCellRow(cell, n, &r, &k);
  const float i = float(k >> 1), rf = float(r);
  const Vec2f up[3] = {{i, rf}, {i + 1.f, rf}, {i, rf + 1.f}};
  const Vec2f down[3] = {{i + 1.f, rf}, {i, rf + 1.f}, {i + 1.f, rf + 1.f}};
  const Vec2f v = (k & 1) ? down[j] : up[j];
  return {v.x / float(n), v.y / float(n)};
}

// The barycentrics (b1, b2) of point q in triangle (p0, p1, p2), for a point on it.
ENVGI_INLINE Vec2f triangleBarycentrics(Vec3f q, Vec3f p0, Vec3f p1, Vec3f p2) {
  const Vec3f e1 = p1 - p0, e2 = p2 - p0, d = q - p0;
  const float d00 = dot(e1, e1), d01 = dot(e1, e2), d11 = dot(e2, e2), d20 = dot(d, e1), d21 = dot(d, e2);
  const float den = d00 * d11 - d01 * d01;
  if (!(den > 0.f)) return {0.f, 0.f};
  return {(d11 * d20 - d01 * d21) / den, (d00 * d21 - d01 * d20) / den};
}

}  // namespace envgi
