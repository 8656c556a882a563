// The 8 grid points around a shading point and their weights, shared by both of the grid's
// bases: trilinear, times 0 for a point inside geometry, and weighted down smoothly for a point
// behind the surface (it sees the other side of it), so light leaks less through walls.
#pragma once

#include "core/Vec.h"

namespace envgi {

struct GridCorners {
  int index[8];
  float weight[8];  // normalised to sum to 1 (all 0 where no point counts)
};

ENVGI_HD inline GridCorners gridCorners(Vec3f lo, Vec3f spacing, int nx, int ny, int nz, const float* pointWeight,
                                        Vec3f p, Vec3f n) {
  GridCorners out;
  Vec3f g((p.x - lo.x) / spacing.x, (p.y - lo.y) / spacing.y, (p.z - lo.z) / spacing.z);
  int i0 = clampi(int(floorf(g.x)), 0, nx - 2), j0 = clampi(int(floorf(g.y)), 0, ny - 2),
      k0 = clampi(int(floorf(g.z)), 0, nz - 2);
  float fx = clampf(g.x - float(i0), 0.f, 1.f), fy = clampf(g.y - float(j0), 0.f, 1.f),
        fz = clampf(g.z - float(k0), 0.f, 1.f);
  float wsum = 0.f;
  for (int c = 0; c < 8; ++c) {
    int di = c & 1, dj = (c >> 1) & 1, dk = (c >> 2) & 1;
    int i = i0 + di, j = j0 + dj, k = k0 + dk;
    out.index[c] = (k * ny + j) * nx + i;
    float w = (di ? fx : 1.f - fx) * (dj ? fy : 1.f - fy) * (dk ? fz : 1.f - fz) * pointWeight[out.index[c]];
    Vec3f toPoint = lo + Vec3f(spacing.x * float(i), spacing.y * float(j), spacing.z * float(k)) - p;
    float len = length(toPoint);
    float facing = len > 0.f ? 0.5f * (1.f + dot(toPoint, n) / len) : 1.f;
    w *= facing * facing + 0.05f;
    out.weight[c] = w > 0.f ? w : 0.f;
    wsum += out.weight[c];
  }
  for (int c = 0; c < 8; ++c) out.weight[c] = wsum > 0.f ? out.weight[c] / wsum : 0.f;
  return out;
}

}  // namespace envgi
