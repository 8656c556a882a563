// Writes Mitsuba .serialized files by its format description (a header and a zlib stream per
// mesh, then a dictionary of offsets and the count), for the reader's tests.
#pragma once

#include <gtest/gtest.h>
#include <zlib.h>

#include <fstream>
#include <string>
#include <vector>

#include "cli/CliRunner.h"
#include "scene/TriangleMesh.h"

namespace envgi::test {

struct Bytes {
  std::vector<unsigned char> b;
  template <class T>
  void put(T v) {
    const auto* p = reinterpret_cast<const unsigned char*>(&v);
    b.insert(b.end(), p, p + sizeof(T));
  }
};

struct MeshData {
  std::vector<double> positions, normals, uvs, colors;
  std::vector<uint32_t> indices;
  bool dbl = false, faceNormals = false;
  std::string name = "mesh";
};

// One mesh's block: the uncompressed header, then its zlib-compressed body.
inline Bytes block(const MeshData& m, uint16_t version) {
  Bytes body;
  uint32_t flags = (m.normals.empty() ? 0 : 1) | (m.uvs.empty() ? 0 : 2) | (m.colors.empty() ? 0 : 8) |
                   (m.faceNormals ? 0x10 : 0) | (m.dbl ? 0x2000 : 0x1000);
  body.put(flags);
  if (version == 4) {
    for (char c : m.name) body.put(c);
    body.put(char(0));
  }
  body.put(uint64_t(m.positions.size() / 3));
  body.put(uint64_t(m.indices.size() / 3));
  for (const auto* a : {&m.positions, &m.normals, &m.uvs, &m.colors})
    for (double v : *a) m.dbl ? body.put(v) : body.put(float(v));
  for (uint32_t i : m.indices) body.put(i);
  uLongf n = compressBound(uLong(body.b.size()));
  std::vector<unsigned char> z(n);
  EXPECT_EQ(compress2(z.data(), &n, body.b.data(), uLong(body.b.size()), 6), Z_OK);
  Bytes out;
  out.put(uint16_t(0x041C));
  out.put(version);
  out.b.insert(out.b.end(), z.begin(), z.begin() + long(n));
  return out;
}

// Meshes one after another, then each one's offset and their count.
inline std::string writeSerialized(const TempDir& d, const std::string& name, const std::vector<MeshData>& meshes,
                            uint16_t version = 4) {
  Bytes file;
  std::vector<uint64_t> offsets;
  for (const MeshData& m : meshes) {
    offsets.push_back(file.b.size());
    Bytes blk = block(m, version);
    file.b.insert(file.b.end(), blk.b.begin(), blk.b.end());
  }
  for (uint64_t o : offsets) version == 4 ? file.put(o) : file.put(uint32_t(o));
  file.put(uint32_t(meshes.size()));
  std::string path = d.file(name);
  std::ofstream(path, std::ios::binary).write(reinterpret_cast<const char*>(file.b.data()), std::streamsize(file.b.size()));
  return path;
}

// A mesh's positions, normals, (u, v) and indices as MeshData (single precision).
inline MeshData meshData(const TriangleMesh& t) {
  MeshData m;
  for (const Vec3f& p : t.positions) m.positions.insert(m.positions.end(), {p.x, p.y, p.z});
  for (const Vec3f& n : t.normals) m.normals.insert(m.normals.end(), {n.x, n.y, n.z});
  for (const Vec2f& uv : t.uvs) m.uvs.insert(m.uvs.end(), {uv.x, uv.y});
  m.indices = t.indices;
  return m;
}

}  // namespace envgi::test
