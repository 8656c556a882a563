#include "scene/TriangleMesh.h"

#include <cmath>
#include <stdexcept>

#include "core/Frame.h"

namespace envgi {

void TriangleMesh::transform(const Transform& t) {
  for (Vec3f& p : positions) p = t.point(p);
  for (Vec3f& n : normals) n = normalize(t.normal(n));
}

namespace {
// The angle between two unit vectors, without acos's loss of precision near 0 and pi.
float angleBetweenUnit(Vec3f a, Vec3f b) {
  return dot(a, b) < 0.f ? kPi - 2.f * std::asin(0.5f * length(a + b)) : 2.f * std::asin(0.5f * length(b - a));
}
}  // namespace

void TriangleMesh::computeVertexNormals() {
  normals.assign(positions.size(), Vec3f(0.f));
  for (size_t i = 0; i + 2 < indices.size(); i += 3) {
    const Vec3f p[3] = {positions[indices[i]], positions[indices[i + 1]], positions[indices[i + 2]]};
    Vec3f n = cross(p[1] - p[0], p[2] - p[0]);
    float l = length(n);
    if (!(l > 0.f)) continue;  // a degenerate triangle has no direction to give
    n = n / l;
    // Each corner adds the face's unit normal times its angle there (Thurmer and Wuthrich
    // 1998): a vertex's normal then follows the surface's shape around it, not the size or
    // number of the triangles that tile it. Mitsuba 3 and Blender weight this way.
    for (int k = 0; k < 3; ++k) {
      Vec3f e1 = p[(k + 1) % 3] - p[k], e2 = p[(k + 2) % 3] - p[k];
      normals[indices[i + k]] += n * angleBetweenUnit(normalize(e1), normalize(e2));
    }
  }
  for (Vec3f& n : normals) {
    float l = length(n);
    n = l > 0.f ? n / l : Vec3f(0.f);
  }
}

void TriangleMesh::validate() const {
  if (indices.empty() || indices.size() % 3 != 0) throw std::runtime_error("mesh '" + name + "' has no triangles");
  for (uint32_t i : indices)
    if (i >= positions.size())
      throw std::runtime_error("mesh '" + name + "': vertex index " + std::to_string(i) + " out of range (" +
                               std::to_string(positions.size()) + " vertices)");
  for (const Vec3f& p : positions)
    if (!isFiniteVec(p)) throw std::runtime_error("mesh '" + name + "' has a non-finite vertex position");
}

TriangleMesh makeRectangle() {
  TriangleMesh m;
  m.name = "rectangle";
  m.positions = {{-1, -1, 0}, {1, -1, 0}, {1, 1, 0}, {-1, 1, 0}};
  m.normals.assign(4, Vec3f(0, 0, 1));
  m.uvs = {{0, 0}, {1, 0}, {1, 1}, {0, 1}};
  m.indices = {0, 1, 2, 0, 2, 3};
  return m;
}

// Mitsuba's cube (u, v) on each face, read from its mesh: each coordinate is (1 +- one of the
// point's coordinates) / 2, the axis and the sign depending on the face.
static Vec2f cubeFaceUv(Vec3f n, Vec3f p) {
  struct Rule {
    int uAxis;
    float uSign;
    int vAxis;
    float vSign;
  };
  // Faces -x, +x, -y, +y, -z, +z.
  static const Rule rules[6] = {{1, 1, 2, 1}, {1, 1, 2, -1}, {2, 1, 0, 1}, {0, -1, 2, -1}, {1, -1, 0, 1}, {1, 1, 0, 1}};
  int axis = n.x != 0.f ? 0 : (n.y != 0.f ? 1 : 2);
  const Rule& r = rules[2 * axis + (n[axis] > 0.f ? 1 : 0)];
  return {0.5f * (1.f + r.uSign * p[r.uAxis]), 0.5f * (1.f + r.vSign * p[r.vAxis])};
}

TriangleMesh makeCube() {
  TriangleMesh m;
  m.name = "cube";
  // Six faces with their own vertices, so each face keeps a flat normal.
  const Vec3f axes[3] = {{1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
  for (int a = 0; a < 3; ++a)
    for (float s : {-1.f, 1.f}) {
      Vec3f n = axes[a] * s, u = axes[(a + 1) % 3], v = axes[(a + 2) % 3];
      if (s < 0.f) std::swap(u, v);  // keep counter-clockwise seen from outside
      uint32_t base = uint32_t(m.positions.size());
      m.positions.push_back(n - u - v);
      m.positions.push_back(n + u - v);
      m.positions.push_back(n + u + v);
      m.positions.push_back(n - u + v);
      for (int k = 0; k < 4; ++k) m.normals.push_back(n);
      for (int k = 0; k < 4; ++k) m.uvs.push_back(cubeFaceUv(n, m.positions[base + uint32_t(k)]));
      for (uint32_t k : {0u, 1u, 2u, 0u, 2u, 3u}) m.indices.push_back(base + k);
    }
  return m;
}

TriangleMesh makeDisk(int segments) {
  TriangleMesh m;
  m.name = "disk";
  // Mitsuba's disk has (u, v) = (radius, azimuth / 2 pi). Each triangle of the fan gets its own
  // centre vertex at its middle azimuth, and the rim closes on a copy of its first vertex at
  // v = 1, so that interpolating (u, v) over a triangle stays close to the exact coordinates.
  for (int i = 0; i <= segments; ++i) {
    float t = float(i) / float(segments), phi = 2.f * kPi * t;
    // The closing vertex is the first one's position exactly (cos and sin of a float 2 pi are
    // not 1 and 0), so that the fan stays watertight at the seam.
    m.positions.push_back(i < segments ? Vec3f(std::cos(phi), std::sin(phi), 0.f) : m.positions[0]);
    m.uvs.push_back({1.f, t});
  }
  for (int i = 0; i < segments; ++i) {
    m.positions.push_back({0, 0, 0});
    m.uvs.push_back({0.f, (float(i) + 0.5f) / float(segments)});
    m.indices.push_back(uint32_t(segments + 1 + i));
    m.indices.push_back(uint32_t(i));
    m.indices.push_back(uint32_t(i + 1));
  }
  m.normals.assign(m.positions.size(), Vec3f(0, 0, 1));
  return m;
}

TriangleMesh makeCylinder(Vec3f p0, Vec3f p1, float radius, int segments) {
  Vec3f d = p1 - p0;
  float len = length(d);
  if (!(radius > 0.f && radius < 1e30f)) throw std::runtime_error("cylinder radius must be positive");
  if (!(len > 0.f && len < 1e30f)) throw std::runtime_error("cylinder p0 and p1 must be two different points");
  // Mitsuba's frame about the axis (the same construction as Frame::fromNormal), so that the
  // azimuth, and with it u, starts where Mitsuba's does.
  Frame axis = Frame::fromNormal(d / len);
  TriangleMesh m;
  m.name = "cylinder";
  // A column of two vertices per azimuth, the last a copy of the first at u = 1 (watertight at
  // the seam, as the disk's rim); normals radial, so shading is as smooth as the analytic shape.
  for (int i = 0; i <= segments; ++i) {
    float u = float(i) / float(segments), phi = 2.f * kPi * u;
    Vec3f radial = i < segments ? axis.s * std::cos(phi) + axis.t * std::sin(phi) : m.normals[0];
    for (float v : {0.f, 1.f}) {
      m.positions.push_back(i < segments ? p0 + radial * radius + d * v : m.positions[size_t(v)]);
      m.normals.push_back(radial);
      m.uvs.push_back({u, v});
    }
  }
  for (int i = 0; i < segments; ++i) {
    uint32_t b0 = uint32_t(2 * i), t0 = b0 + 1, b1 = b0 + 2, t1 = b0 + 3;
    for (uint32_t k : {b0, b1, t1, b0, t1, t0}) m.indices.push_back(k);  // counter-clockwise from outside
  }
  return m;
}

}  // namespace envgi
