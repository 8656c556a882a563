// Vertex normals made for meshes that come without them.
#include <gtest/gtest.h>

#include <cmath>

#include "scene/TriangleMesh.h"

using namespace envgi;

namespace {

// The angle at corner a of triangle (a, b, c), in double precision.
double cornerAngle(Vec3f a, Vec3f b, Vec3f c) {
  double ux = b.x - a.x, uy = b.y - a.y, uz = b.z - a.z, vx = c.x - a.x, vy = c.y - a.y, vz = c.z - a.z;
  double d = ux * vx + uy * vy + uz * vz;
  return std::acos(d / (std::sqrt(ux * ux + uy * uy + uz * uz) * std::sqrt(vx * vx + vy * vy + vz * vz)));
}

}  // namespace

// A vertex shared by a large face with a small angle and a small face with a large one: each face
// counts by its angle at the vertex (as Mitsuba 3 weighs), not by its area.
TEST(TriangleMesh, VertexNormalsWeighFacesByTheirAngle) {
  TriangleMesh m;
  // Face A lies in z = 0 (normal +z): long and thin at vertex 0. Face B lies in x = 0 (normal
  // +x): small, with a right angle at vertex 0.
  m.positions = {{0, 0, 0}, {4, 0, 0}, {4, 1, 0}, {0, 0, 1}, {0, 0.5f, 0}, {9, 9, 9}};
  m.indices = {0, 1, 2, 0, 4, 3};
  m.computeVertexNormals();
  ASSERT_EQ(m.normals.size(), m.positions.size());
  double angleA = cornerAngle(m.positions[0], m.positions[1], m.positions[2]);
  double angleB = cornerAngle(m.positions[0], m.positions[4], m.positions[3]);
  double nx = angleB, nz = angleA, l = std::hypot(nx, nz);
  EXPECT_NEAR(m.normals[0].x, nx / l, 1e-5);
  EXPECT_NEAR(m.normals[0].y, 0.0, 1e-6);
  EXPECT_NEAR(m.normals[0].z, nz / l, 1e-5);
  // Area weighting would lean the other way: face A's area is 8 times face B's.
  EXPECT_GT(m.normals[0].x, m.normals[0].z);
  // A vertex of one face takes that face's normal; one no face uses keeps none.
  EXPECT_NEAR(m.normals[1].z, 1.f, 1e-6);
  EXPECT_NEAR(m.normals[3].x, 1.f, 1e-6);
  EXPECT_EQ(m.normals[5].x, 0.f);
  EXPECT_EQ(m.normals[5].y, 0.f);
  EXPECT_EQ(m.normals[5].z, 0.f);
}

// A triangle with no area (repeated or collinear corners) adds nothing and leaves no NaN.
TEST(TriangleMesh, DegenerateTrianglesAddNothing) {
  TriangleMesh m;
  m.positions = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {2, 0, 0}};
  m.indices = {0, 1, 2, 0, 0, 1, 0, 1, 3};
  m.computeVertexNormals();
  for (int v = 0; v < 3; ++v) {
    EXPECT_NEAR(m.normals[v].z, 1.f, 1e-6) << v;
    EXPECT_TRUE(std::isfinite(m.normals[v].x)) << v;
  }
  EXPECT_EQ(m.normals[3].z, 0.f);  // only in the collinear triangle
}
