// A triangle mesh on the host: the storage a MeshView points into.
#pragma once

#include <string>
#include <vector>

#include "core/Transform.h"

namespace envgi {

struct TriangleMesh {
  std::string name;
  std::vector<Vec3f> positions;
  std::vector<Vec3f> normals;  // empty or one per position
  std::vector<Vec2f> uvs;      // empty or one per position
  std::vector<uint32_t> indices;

  size_t triangleCount() const { return indices.size() / 3; }
  void transform(const Transform& t);
  // Angle-weighted vertex normals, as Mitsuba 3 computes for meshes that have none.
  void computeVertexNormals();
  // Throws when an index is out of range or a coordinate is not finite.
  void validate() const;
  size_t bytes() const {
    return positions.size() * sizeof(Vec3f) + normals.size() * sizeof(Vec3f) + uvs.size() * sizeof(Vec2f) +
           indices.size() * sizeof(uint32_t);
  }
};

// Stanford PLY (ascii, binary little- and big-endian): vertex x y z [nx ny nz] [u v | s t],
// face vertex_indices (polygons are fanned). Errors name the file and what is wrong.
TriangleMesh loadPly(const std::string& path);
// Wavefront OBJ through tinyobjloader; all groups become one mesh.
TriangleMesh loadObj(const std::string& path);
// Mitsuba's .serialized (versions 3 and 4; zlib): mesh shapeIndex of the file, its positions,
// normals and (u, v) where it has them (vertex colours are skipped, as Mitsuba does);
// *faceNormals, where given, gets the file's face-normals flag.
TriangleMesh loadSerialized(const std::string& path, int shapeIndex = 0, bool* faceNormals = nullptr);

// Mitsuba's analytic shapes as meshes: rectangle [-1,1]^2 at z=0 facing +z, cube [-1,1]^3,
// disk of radius 1 at z=0 facing +z (tessellated into `segments` triangles), and the open
// cylinder about p0 -> p1 (no caps, normals outward; `segments` quads around), with Mitsuba's
// (u, v) = (azimuth / 2 pi, distance along the axis / its length).
TriangleMesh makeRectangle();
TriangleMesh makeCube();
TriangleMesh makeDisk(int segments = 128);
TriangleMesh makeCylinder(Vec3f p0, Vec3f p1, float radius, int segments = 256);

}  // namespace envgi
