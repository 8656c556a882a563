// A triangle's n^2 cells (TriangleCells.h): a point drawn in a cell is found in that cell, the
// cells tile the triangle evenly (chi-square of uniform points' cells), and a point is drawn
// uniformly inside its cell. A sphere's 2 n^2 cells (SphereCells.h): the same, by area.
#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "sampling/Pcg32.h"
#include "sampling/SphereCells.h"
#include "sampling/TriangleCells.h"
#include "sampling/Warp.h"
#include "support/ChiSquare.h"
#include "support/TestScenes.h"

using namespace envgi;

namespace {
// (b1, b2) of p in the triangle with corners a, b, c given as barycentrics.
Vec2f relative(Vec2f p, Vec2f a, Vec2f b, Vec2f c) {
  const float det = (b.x - a.x) * (c.y - a.y) - (c.x - a.x) * (b.y - a.y);
  const float s = ((p.x - a.x) * (c.y - a.y) - (c.x - a.x) * (p.y - a.y)) / det;
  const float t = ((b.x - a.x) * (p.y - a.y) - (p.x - a.x) * (b.y - a.y)) / det;
  return {s, t};
}
}  // namespace

TEST(TriangleCells, ADrawnPointLiesInItsCell) {
  Pcg32 rng(3, 1);
  for (int n : {1, 2, 3, 7, 64, 256}) {
    for (int cell = 0; cell < n * n; cell += (n > 8 ? 37 : 1)) {
      const Vec2f c0 = triangleCellCorner(cell, n, 0), c1 = triangleCellCorner(cell, n, 1), c2 = triangleCellCorner(cell, n, 2);
      // Every cell has a ninth, a 49th, ... of the triangle's area (0.5 in barycentrics).
      const float area = 0.5f * std::fabs((c1.x - c0.x) * (c2.y - c0.y) - (c2.x - c0.x) * (c1.y - c0.y));
      EXPECT_NEAR(area, 0.5f / float(n * n), 1e-4f / float(n * n)) << n << " cell " << cell;
      for (int i = 0; i < 8; ++i) {
        // Away from the cell's edges, where float error may put a point next door.
        const Vec2f u(0.05f + 0.9f * rng.nextFloat(), 0.05f + 0.9f * rng.nextFloat());
        const Vec2f b = sampleTriangleCell(cell, n, u);
        ASSERT_GE(b.x, 0.f);
        ASSERT_GE(b.y, 0.f);
        ASSERT_LE(b.x + b.y, 1.f + 1e-6f);
        const Vec2f r = relative(b, c0, c1, c2);
        EXPECT_GE(r.x, -1e-3f) << n << " cell " << cell;
        EXPECT_GE(r.y, -1e-3f) << n << " cell " << cell;
        EXPECT_LE(r.x + r.y, 1.f + 1e-3f) << n << " cell " << cell;
        if (u.x + u.y > 0.2f && u.x + u.y < 1.8f) {
          EXPECT_EQ(triangleCellOf(b, n), cell) << n;
        }
      }
    }
  }
}

// Uniform points over the triangle fall in each of its 49 cells alike.
TEST(TriangleCells, CellsTileTheTriangleEvenly) {
  const int n = 7, cells = n * n, samples = 196000;
  std::vector<double> count(cells, 0.0);
  Pcg32 rng(11, 2);
  for (int i = 0; i < samples; ++i) {
    const Vec2f b = sampleUniformTriangle(Vec2f(rng.nextFloat(), rng.nextFloat()));
    const int c = triangleCellOf(b, n);
    ASSERT_GE(c, 0);
    ASSERT_LT(c, cells);
    count[size_t(c)] += 1.0;
  }
  double chi2 = 0.0, expected = double(samples) / cells;
  for (double k : count) chi2 += (k - expected) * (k - expected) / expected;
  const double p = test::gammaQ(0.5 * (cells - 1), 0.5 * chi2);
  EXPECT_GT(p, 1e-3) << "chi2 " << chi2;
}

// Inside a cell, points are uniform: their mean is its centroid and each half of it (cut along
// a median) takes half of them.
TEST(TriangleCells, PointsAreUniformInsideTheirCell) {
  Pcg32 rng(5, 3);
  for (int n : {3, 16})
    for (int cell : {0, 1, n * n - 1, n + 1}) {
      const Vec2f c0 = triangleCellCorner(cell, n, 0), c1 = triangleCellCorner(cell, n, 1), c2 = triangleCellCorner(cell, n, 2);
      const int m = 40000;
      Vec2f mean(0.f, 0.f);
      int below = 0;
      for (int i = 0; i < m; ++i) {
        const Vec2f b = sampleTriangleCell(cell, n, Vec2f(rng.nextFloat(), rng.nextFloat()));
        mean = mean + b * (1.f / float(m));
        below += relative(b, c0, c1, c2).x < relative(b, c0, c1, c2).y;
      }
      const Vec2f centroid = (c0 + c1 + c2) * (1.f / 3.f);
      EXPECT_NEAR(mean.x, centroid.x, 0.01f / float(n)) << n << " cell " << cell;
      EXPECT_NEAR(mean.y, centroid.y, 0.01f / float(n)) << n << " cell " << cell;
      test::expectShare(below, m, 0.5, "a median halves the cell");
    }
}

// A sphere's cells: their shares of the area sum to 1, a direction drawn in a cell is found
// there, and uniform directions fall in each cell by its share (chi-square over 72 cells).
TEST(SphereCells, CellsTileTheSphereByArea) {
  const int n = 6, cells = sphereCellCount(n), samples = 288000;
  double shares = 0.0;
  Pcg32 rng(13, 6);
  for (int c = 0; c < cells; ++c) {
    shares += sphereCellShare(c, n);
    for (int i = 0; i < 4; ++i) {
      const Vec3f d = sampleSphereCell(c, n, Vec2f(0.05f + 0.9f * rng.nextFloat(), 0.05f + 0.9f * rng.nextFloat()));
      EXPECT_NEAR(length(d), 1.f, 1e-5f);
      float phi = std::atan2(d.y, d.x);
      if (phi < 0.f) phi += 2.f * kPi;
      const Vec2f uv(phi / (2.f * kPi), std::acos(std::fmin(std::fmax(d.z, -1.f), 1.f)) / kPi);
      EXPECT_EQ(sphereCellOf(uv, n), c);
    }
  }
  EXPECT_NEAR(shares, 1.0, 1e-5);
  std::vector<double> count(size_t(cells), 0.0);
  for (int i = 0; i < samples; ++i) {
    const Vec3f d = sampleUniformSphere(Vec2f(rng.nextFloat(), rng.nextFloat()));
    float phi = std::atan2(d.y, d.x);
    if (phi < 0.f) phi += 2.f * kPi;
    count[size_t(sphereCellOf(Vec2f(phi / (2.f * kPi), std::acos(std::fmin(std::fmax(d.z, -1.f), 1.f)) / kPi), n))] += 1.0;
  }
  double chi2 = 0.0;
  for (int c = 0; c < cells; ++c) {
    const double expected = samples * double(sphereCellShare(c, n));
    chi2 += (count[size_t(c)] - expected) * (count[size_t(c)] - expected) / expected;
  }
  EXPECT_GT(test::gammaQ(0.5 * (cells - 1), 0.5 * chi2), 1e-3) << "chi2 " << chi2;
}

// Inside a sphere cell, directions are uniform by area: the share of them above the cell's
// middle height (z) is one half, and their azimuths split evenly at the cell's middle one.
TEST(SphereCells, PointsAreUniformInsideTheirCell) {
  Pcg32 rng(17, 7);
  const int n = 5;
  for (int c : {0, 3, 2 * n * 2 + 1, sphereCellCount(n) - 1}) {
    const int iv = c / (2 * n), iu = c - iv * 2 * n;
    const float z0 = std::cos(kPi * float(iv) / float(n)), z1 = std::cos(kPi * float(iv + 1) / float(n));
    const float midPhi = 2.f * kPi * (float(iu) + 0.5f) / float(2 * n);
    const int m = 40000;
    int upper = 0, before = 0;
    for (int i = 0; i < m; ++i) {
      const Vec3f d = sampleSphereCell(c, n, Vec2f(rng.nextFloat(), rng.nextFloat()));
      upper += d.z > 0.5f * (z0 + z1);
      float phi = std::atan2(d.y, d.x);
      if (phi < 0.f) phi += 2.f * kPi;
      before += phi < midPhi;
    }
    test::expectShare(upper, m, 0.5, "uniform in z (Archimedes): half above the middle height");
    test::expectShare(before, m, 0.5, "uniform in azimuth");
  }
}
