// Mitsuba's .serialized meshes: files written here by its format description (a header and a
// zlib stream per mesh, a dictionary of offsets at the end) read back to the same floats, in
// both versions and precisions; damaged files give clear errors.
#include <gtest/gtest.h>
#include <zlib.h>

#include <cstring>
#include <fstream>
#include <stdexcept>

#include "cli/CliRunner.h"
#include "scene/TriangleMesh.h"
#include "support/SerializedFile.h"

using namespace envgi;
using namespace envgi::test;

namespace {

MeshData triangle() {
  MeshData m;
  m.positions = {0, 0, 0, 1, 0, 0, 0, 1, 0};
  m.normals = {0, 0, 1, 0, 0, 1, 0, 0, 1};
  m.uvs = {0, 0, 1, 0, 0, 1};
  m.indices = {0, 1, 2};
  m.name = "tri";
  return m;
}

MeshData quad(bool dbl) {
  MeshData m;
  m.positions = {0.1, 0.2, 0.3, 2, 0, 0, 2, 2, 0, 0, 2, 1.0 / 3.0};
  m.colors = {1, 0, 0, 0, 1, 0, 0, 0, 1, 1, 1, 1};  // skipped
  m.indices = {0, 1, 2, 0, 2, 3};
  m.dbl = dbl;
  m.faceNormals = true;
  return m;
}

std::string loadError(const std::string& path, int index = 0) {
  try {
    loadSerialized(path, index);
  } catch (const std::runtime_error& e) {
    return e.what();
  }
  return "";
}

}  // namespace

TEST(SerializedReader, ReadsEachMeshOfTheFileInBothVersions) {
  test::TempDir d;
  for (uint16_t version : {uint16_t(3), uint16_t(4)}) {
    std::string path = writeSerialized(d, "m" + std::to_string(version) + ".serialized", {triangle(), quad(true), quad(false)}, version);
    bool faceNormals = true;
    TriangleMesh a = loadSerialized(path, 0, &faceNormals);
    EXPECT_FALSE(faceNormals);
    ASSERT_EQ(a.positions.size(), 3u);
    EXPECT_EQ(a.positions[1].x, 1.f);
    ASSERT_EQ(a.normals.size(), 3u);
    EXPECT_EQ(a.normals[2].z, 1.f);
    ASSERT_EQ(a.uvs.size(), 3u);
    EXPECT_EQ(a.uvs[2].y, 1.f) << "v as stored (Mitsuba's serialized loader flips nothing)";
    EXPECT_EQ(a.indices, std::vector<uint32_t>({0, 1, 2}));
    if (version == 4) EXPECT_EQ(a.name, "tri");
    for (int k : {1, 2}) {
      TriangleMesh b = loadSerialized(path, k, &faceNormals);
      EXPECT_TRUE(faceNormals);
      ASSERT_EQ(b.positions.size(), 4u);
      EXPECT_TRUE(b.normals.empty() && b.uvs.empty());
      EXPECT_EQ(b.positions[0].y, 0.2f);
      EXPECT_EQ(b.positions[3].z, float(1.0 / 3.0)) << (k == 1 ? "double" : "single") << " precision";
      EXPECT_EQ(b.indices, std::vector<uint32_t>({0, 1, 2, 0, 2, 3})) << "after the skipped colours";
    }
  }
}

TEST(SerializedReader, DamagedFilesGiveClearErrors) {
  test::TempDir d;
  std::string good = writeSerialized(d, "good.serialized", {triangle(), quad(false)});
  std::ifstream in(good, std::ios::binary);
  std::vector<char> bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  auto variant = [&](const std::string& name, std::vector<char> b) {
    std::ofstream(d.file(name), std::ios::binary).write(b.data(), std::streamsize(b.size()));
    return d.file(name);
  };
  EXPECT_NE(loadError(good, 2).find("shape_index 2 is out of range (the file holds 2 meshes)"), std::string::npos);
  EXPECT_NE(loadError(good, -1).find("must not be negative"), std::string::npos);
  std::vector<char> b = bytes;
  b[0] = 'P';
  EXPECT_NE(loadError(variant("magic.serialized", b)).find("not a Mitsuba .serialized mesh"), std::string::npos);
  b = bytes;
  b[2] = 5;
  EXPECT_NE(loadError(variant("version.serialized", b)).find("version 5"), std::string::npos);
  // Cut inside the first mesh's compressed data.
  b.assign(bytes.begin(), bytes.begin() + 30);
  std::string cut = loadError(variant("cut.serialized", b));
  EXPECT_TRUE(cut.find("truncated") != std::string::npos || cut.find("ends early") != std::string::npos ||
              cut.find("corrupt") != std::string::npos)
      << cut;
  b = bytes;
  for (int i = 12; i < 20; ++i) b[size_t(i)] = char(0x55);
  EXPECT_FALSE(loadError(variant("corrupt.serialized", b)).empty());
  // A dictionary that points past the file.
  b = bytes;
  uint64_t far = 1u << 30;
  std::memcpy(b.data() + b.size() - 12, &far, 8);
  EXPECT_NE(loadError(variant("dict.serialized", b), 1).find("does not start with the 0x041C header"), std::string::npos);
  // One so near 2^64 that offset + 4 wraps round to a small number (found by the mesh fuzzer).
  b = bytes;
  far = ~uint64_t(0) - 1;
  std::memcpy(b.data() + b.size() - 12, &far, 8);
  EXPECT_NE(loadError(variant("wrap.serialized", b), 1).find("does not start with the 0x041C header"), std::string::npos);
  // A triangle whose index is past the vertices: validate()'s error.
  MeshData bad = triangle();
  bad.indices = {0, 1, 7};
  EXPECT_FALSE(loadError(writeSerialized(d, "index.serialized", {bad})).empty());
  // Counts far larger than the data: truncated, not a huge allocation.
  Bytes body;
  body.put(uint32_t(0x1000));
  body.put(char(0));
  body.put(uint64_t(4000000000ull));
  body.put(uint64_t(1));
  uLongf n = compressBound(uLong(body.b.size()));
  std::vector<unsigned char> z(n);
  compress2(z.data(), &n, body.b.data(), uLong(body.b.size()), 6);
  Bytes file;
  file.put(uint16_t(0x041C));
  file.put(uint16_t(4));
  file.b.insert(file.b.end(), z.begin(), z.begin() + long(n));
  std::vector<char> raw(file.b.begin(), file.b.end());
  EXPECT_NE(loadError(variant("huge.serialized", raw)).find("ends early"), std::string::npos)
      << loadError(variant("huge.serialized", raw));
}
