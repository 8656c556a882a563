#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>

#include "cli/CliRunner.h"
#include "core/Frame.h"
#include "scene/TriangleMesh.h"

using namespace envgi;
namespace fs = std::filesystem;

namespace {

const char* kAsciiPly =
    "ply\nformat ascii 1.0\ncomment a quad\nelement vertex 4\nproperty float x\nproperty float y\nproperty float z\n"
    "property float nx\nproperty float ny\nproperty float nz\nelement face 1\nproperty list uchar int vertex_indices\n"
    "end_header\n0 0 0 0 0 1\n1 0 0 0 0 1\n1 1 0 0 0 1\n0 1 0 0 0 1\n4 0 1 2 3\n";

std::string binaryPly(bool bigEndian) {
  std::string s = std::string("ply\nformat ") + (bigEndian ? "binary_big_endian" : "binary_little_endian") +
                  " 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\n"
                  "element face 1\nproperty list uchar uint vertex_indices\nend_header\n";
  auto put = [&](const void* p, size_t n) {
    std::string b(static_cast<const char*>(p), n);
    if (bigEndian) std::reverse(b.begin(), b.end());
    s += b;
  };
  float v[9] = {0, 0, 0, 2, 0, 0, 0, 3, 0};
  for (float x : v) put(&x, 4);
  unsigned char n = 3;
  s += char(n);
  for (uint32_t i : {0u, 1u, 2u}) put(&i, 4);
  return s;
}

void write(const std::string& path, const std::string& s) { std::ofstream(path, std::ios::binary) << s; }

template <class F>
void expectError(F&& f, const std::string& expect) {
  try {
    f();
    ADD_FAILURE() << "no error for: " << expect;
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find(expect), std::string::npos) << e.what();
  }
}

}  // namespace

TEST(MeshIO, AsciiPlyWithNormalsAndQuad) {
  test::TempDir d;
  write(d.file("q.ply"), kAsciiPly);
  TriangleMesh m = loadPly(d.file("q.ply"));
  EXPECT_EQ(m.positions.size(), 4u);
  EXPECT_EQ(m.triangleCount(), 2u);  // the quad is fanned
  ASSERT_EQ(m.normals.size(), 4u);
  EXPECT_EQ(m.normals[2].z, 1.f);
}

TEST(MeshIO, BinaryPlyBothEndians) {
  test::TempDir d;
  for (bool be : {false, true}) {
    write(d.file("b.ply"), binaryPly(be));
    TriangleMesh m = loadPly(d.file("b.ply"));
    ASSERT_EQ(m.triangleCount(), 1u);
    EXPECT_EQ(m.positions[1].x, 2.f);
    EXPECT_EQ(m.positions[2].y, 3.f);
    EXPECT_EQ(m.indices[2], 2u);
  }
}

TEST(MeshIO, MalformedPlyGivesClearErrors) {
  test::TempDir d;
  std::string full = binaryPly(false);
  struct Bad {
    std::string content, expect;
  };
  std::string ascii = kAsciiPly;
  std::vector<Bad> bad = {
      {full.substr(0, 40), "end_header"},                                // cut inside the header
      {full.substr(0, full.size() - 5), "unexpected end of file"},       // cut inside the data
      {ascii.substr(0, ascii.size() - 12), "unexpected end of file"},    // ascii cut
      {"plx\n", "not a PLY file"},
      {std::string(kAsciiPly).replace(ascii.find("4 0 1 2 3"), 9, "3 0 1 9"), "refers to vertex 9"},
      {std::string(kAsciiPly).replace(ascii.find("property float x"), 16, "property quux x"), "unknown property type"},
      {std::string(kAsciiPly).replace(ascii.find("1 1 0 0"), 7, "1 a 0 0"), "expected a number"},
      // Counts the bytes left cannot hold fail before anything is allocated for them, and an
      // element without properties is not read item by item (found by tests/fuzz).
      {std::string(kAsciiPly).replace(ascii.find("vertex 4"), 8, "vertex 4000000000000"), "declares 4000000000000 items"},
      {std::string(kAsciiPly).replace(ascii.find("4 0 1 2 3"), 9, "nan 0 1 2 3"), "bad vertex count"},
      {std::string(kAsciiPly).replace(ascii.find("4 0 1 2 3"), 9, "3 0 1 nan"), "refers to vertex nan"},
  };
  for (const Bad& b : bad) {
    write(d.file("bad.ply"), b.content);
    try {
      loadPly(d.file("bad.ply"));
      ADD_FAILURE() << "no error for: " << b.expect;
    } catch (const std::runtime_error& e) {
      EXPECT_NE(std::string(e.what()).find(b.expect), std::string::npos) << e.what();
    }
  }
}

TEST(MeshIO, PlyElementWithoutPropertiesTakesNoBytes) {
  // It used to be read item by item: a count of 9e18 hung the reader (found by tests/fuzz).
  test::TempDir d;
  std::string ascii = kAsciiPly;
  write(d.file("e.ply"), ascii.replace(ascii.find("element face"), 0, "element edge 8888888888888888888\n"));
  EXPECT_EQ(loadPly(d.file("e.ply")).triangleCount(), 2u);
}

TEST(MeshIO, ObjAndErrors) {
  test::TempDir d;
  write(d.file("t.obj"), "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nvn 0 0 1\nf 1//1 2//1 3//1 4//1\n");
  TriangleMesh m = loadObj(d.file("t.obj"));
  EXPECT_EQ(m.triangleCount(), 2u);
  EXPECT_EQ(m.normals.size(), m.positions.size());
  // tinyobjloader leaves the normal and uv indices unchecked (found by tests/fuzz).
  write(d.file("n.obj"), "v 0 0 0\nv 1 0 0\nv 1 1 0\nvn 0 0 1\nf 1//1 2//1 3//2\n");
  expectError([&] { loadObj(d.file("n.obj")); }, "normal index out of range");
  write(d.file("t.obj"), "v 0 0 0\nv 1 0 0\nv 1 1 0\nvt 0 0\nf 1/1 2/1 3/2\n");
  expectError([&] { loadObj(d.file("t.obj")); }, "texture coordinate index out of range");
  write(d.file("empty.obj"), "v 0 0 0\nv 1 0 0\n");
  EXPECT_THROW(loadObj(d.file("empty.obj")), std::runtime_error);
  EXPECT_THROW(loadObj(d.file("missing.obj")), std::runtime_error);
}

// tinyobjloader reads a number it cannot parse, and a coordinate that is missing, as 0: such a
// line moved its vertex to the origin without a word; and it dropped a face of two vertices.
// Now each is an error naming the line.
TEST(MeshIO, ObjNumbersThatAreNotNumbersAreErrors) {
  test::TempDir d;
  const std::string face = "f 1 2 3\n";
  const std::pair<std::string, std::string> bad[] = {
      {"v 0 0 0\nv 1 0 abc\nv 0 1 0\n", "line 2: 'abc' is not a finite number"},
      {"v 0 0 0\nv 1 0 0\nv 0 1 nan\n", "line 3: 'nan' is not a finite number"},
      {"v 0 0 1e999\nv 1 0 0\nv 0 1 0\n", "line 1: '1e999' is not a finite number"},
      {"v 0 0 0\nv 1 0 0\nv 0 1\n", "line 3: v needs 3 coordinates, it has 2"},
      {"v 0 0 0\nv 1 0 0\nv 0 1 0\nvn 0 1\n", "line 4: vn needs 3 coordinates, it has 2"},
      {"v 0 0 0\nv 1 0 0\nv 0 1 0\nvt\n", "line 4: vt needs 1 coordinate, it has 0"},
      {"v 0 0 0\nv 1 0 0\nv 0 1 +-1\n", "line 3: '+-1' is not a finite number"},
      // tinyobjloader dropped such a face; PLY's reader refuses it too.
      {"v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\nf 1 2 # edge\n", "line 5: a face needs 3 vertices or more, it has 2"},
  };
  for (const auto& [text, message] : bad) {
    write(d.file("bad.obj"), text + face);
    expectError([&] { loadObj(d.file("bad.obj")); }, message);
  }
  // What OBJ writers do write: a '+', a w, a comment after the numbers, CRLF, a "vp" line.
  write(d.file("ok.obj"), "v +0 0 0 # origin\r\nv 1 0 0 1.0\r\nv 0 1 -0.0\r\nvt 0.5\r\nvp 0.1 0.2\r\n" + face);
  TriangleMesh m = loadObj(d.file("ok.obj"));
  EXPECT_EQ(m.triangleCount(), 1u);
  EXPECT_EQ(m.positions[1].x, 1.f);
}

TEST(MeshIO, SharedAssetsLoad) {
  std::string buddha = std::string(ENVGI_ASSETS_DIR) + "/meshes/happy_buddha/happy_buddha_100k.ply";
  std::string dragon = std::string(ENVGI_ASSETS_DIR) + "/meshes/dragon/dragon_vrip.ply";
  if (!fs::exists(buddha)) GTEST_SKIP() << "assets not found in " << ENVGI_ASSETS_DIR;
  TriangleMesh b = loadPly(buddha);
  EXPECT_EQ(b.triangleCount(), 100000u);
  if (fs::exists(dragon)) {
    TriangleMesh dr = loadPly(dragon);
    EXPECT_EQ(dr.triangleCount(), 871414u);
    dr.computeVertexNormals();
    // Positions, normals and indices: about 24 bytes a triangle.
    EXPECT_LT(double(dr.bytes()) / dr.triangleCount(), 40.0);
  }
}

TEST(MeshIO, PrimitivesAreClosedAndOriented) {
  TriangleMesh c = makeCube();
  EXPECT_EQ(c.triangleCount(), 12u);
  // Every face normal points away from the centre.
  for (size_t t = 0; t < c.triangleCount(); ++t) {
    Vec3f p0 = c.positions[c.indices[3 * t]], p1 = c.positions[c.indices[3 * t + 1]], p2 = c.positions[c.indices[3 * t + 2]];
    EXPECT_GT(dot(cross(p1 - p0, p2 - p0), p0 + p1 + p2), 0.f);
  }
  TriangleMesh r = makeRectangle();
  Vec3f n = cross(r.positions[1] - r.positions[0], r.positions[2] - r.positions[0]);
  EXPECT_GT(n.z, 0.f);
  TriangleMesh disk = makeDisk(64);
  double area = 0.0;
  for (size_t t = 0; t < disk.triangleCount(); ++t) {
    Vec3f p0 = disk.positions[disk.indices[3 * t]], p1 = disk.positions[disk.indices[3 * t + 1]],
          p2 = disk.positions[disk.indices[3 * t + 2]];
    area += 0.5 * length(cross(p1 - p0, p2 - p0));
    EXPECT_GT(cross(p1 - p0, p2 - p0).z, 0.f);
  }
  EXPECT_NEAR(area, M_PI, 0.01);
}

// The primitives' (u, v) as Mitsuba 3.9.1 gives them: its cube mesh's texture coordinates at six
// corners (one a face, read from mi.traverse of a cube), and its disk's (radius, azimuth / 2 pi)
// inside a fan triangle, within the tessellation's error.
TEST(MeshIO, PrimitivesHaveMitsubasSurfaceCoordinates) {
  TriangleMesh c = makeCube();
  ASSERT_EQ(c.uvs.size(), c.positions.size());
  struct Corner {
    Vec3f p, n;
    Vec2f uv;
  } corners[] = {{{1, -1, -1}, {0, -1, 0}, {0, 1}}, {{-1, 1, -1}, {0, 1, 0}, {1, 1}}, {{1, 1, 1}, {1, 0, 0}, {1, 0}},
                 {{-1, 1, 1}, {0, 0, 1}, {1, 0}},   {{-1, -1, 1}, {-1, 0, 0}, {0, 1}}, {{1, -1, -1}, {0, 0, -1}, {1, 1}}};
  for (const Corner& k : corners) {
    int found = 0;
    for (size_t i = 0; i < c.positions.size(); ++i)
      if (length(c.positions[i] - k.p) < 1e-6f && length(c.normals[i] - k.n) < 1e-6f) {
        EXPECT_EQ(c.uvs[i].x, k.uv.x) << k.p.x << k.p.y << k.p.z;
        EXPECT_EQ(c.uvs[i].y, k.uv.y) << k.p.x << k.p.y << k.p.z;
        ++found;
      }
    EXPECT_EQ(found, 1);
  }
  TriangleMesh disk = makeDisk(128);
  ASSERT_EQ(disk.uvs.size(), disk.positions.size());
  // The seam's last triangle ends on the first rim vertex's position, to the bit.
  uint32_t closing = disk.indices[3 * (disk.triangleCount() - 1) + 2];
  EXPECT_EQ(disk.positions[closing].x, disk.positions[disk.indices[1]].x);
  EXPECT_EQ(disk.positions[closing].y, disk.positions[disk.indices[1]].y);
  for (size_t t = 0; t < disk.triangleCount(); t += 7) {
    uint32_t i0 = disk.indices[3 * t], i1 = disk.indices[3 * t + 1], i2 = disk.indices[3 * t + 2];
    for (Vec3f b : {Vec3f(0.2f, 0.4f, 0.4f), Vec3f(0.7f, 0.1f, 0.2f), Vec3f(0.05f, 0.9f, 0.05f)}) {
      Vec3f p = disk.positions[i0] * b.x + disk.positions[i1] * b.y + disk.positions[i2] * b.z;
      Vec2f uv = disk.uvs[i0] * b.x + disk.uvs[i1] * b.y + disk.uvs[i2] * b.z;
      float phi = std::atan2(p.y, p.x);
      if (phi < 0.f) phi += 2.f * float(M_PI);
      EXPECT_NEAR(uv.x, length(p), 1e-3f) << t;
      EXPECT_NEAR(uv.y, phi / (2.f * float(M_PI)), 1e-3f) << t;
    }
  }
}

// Mitsuba's cylinder as a mesh, along an oblique axis: its vertices lie on the surface of radius
// r about p0 -> p1, between the two ends; its faces face outward along their vertices' normals;
// its area is 2 pi r L less the tessellation's chords; (u, v) inside a triangle is Mitsuba's
// (azimuth / 2 pi in the axis's frame, distance along the axis / L); the seam closes to the bit.
TEST(MeshIO, CylinderIsMitsubasAboutItsAxis) {
  const Vec3f p0(1.f, -0.5f, 2.f), p1(0.2f, 1.5f, 2.6f);
  const float r = 0.4f, len = length(p1 - p0);
  const Vec3f axis = (p1 - p0) / len;
  TriangleMesh c = makeCylinder(p0, p1, r, 64);
  ASSERT_EQ(c.triangleCount(), 128u);
  ASSERT_EQ(c.uvs.size(), c.positions.size());
  ASSERT_EQ(c.normals.size(), c.positions.size());
  Frame f = Frame::fromNormal(axis);
  double area = 0.0;
  for (size_t t = 0; t < c.triangleCount(); ++t) {
    uint32_t i0 = c.indices[3 * t], i1 = c.indices[3 * t + 1], i2 = c.indices[3 * t + 2];
    Vec3f a = c.positions[i0], b = c.positions[i1], d = c.positions[i2];
    Vec3f n = cross(b - a, d - a);
    area += 0.5 * length(n);
    EXPECT_GT(dot(n, c.normals[i0] + c.normals[i1] + c.normals[i2]), 0.f) << t;
    for (Vec3f w : {Vec3f(0.2f, 0.4f, 0.4f), Vec3f(0.7f, 0.1f, 0.2f), Vec3f(0.05f, 0.9f, 0.05f)}) {
      Vec3f p = a * w.x + b * w.y + d * w.z;
      Vec2f uv = c.uvs[i0] * w.x + c.uvs[i1] * w.y + c.uvs[i2] * w.z;
      Vec3f q = f.toLocal(p - p0);
      float phi = std::atan2(q.y, q.x);
      if (phi < 0.f) phi += 2.f * float(M_PI);
      // Just after the seam atan2 gives 0 where the last quad's u is near 1.
      float du = std::fabs(uv.x - phi / (2.f * float(M_PI)));
      EXPECT_LT(std::min(du, 1.f - du), 2e-3f) << t;
      EXPECT_NEAR(uv.y, q.z / len, 1e-5f) << t;
    }
  }
  for (size_t i = 0; i < c.positions.size(); ++i) {
    Vec3f q = f.toLocal(c.positions[i] - p0);
    EXPECT_NEAR(std::hypot(q.x, q.y), r, 1e-5f);
    EXPECT_TRUE(std::fabs(q.z) < 1e-5f || std::fabs(q.z - len) < 1e-5f);
    EXPECT_NEAR(length(c.normals[i]), 1.f, 1e-5f);
    EXPECT_NEAR(dot(c.normals[i], axis), 0.f, 1e-5f);
  }
  const double chord = 64.0 * std::sin(M_PI / 64.0) / M_PI;  // the polygon's perimeter over the circle's
  EXPECT_NEAR(area, 2.0 * M_PI * r * len * chord, 1e-4);
  const size_t last = c.positions.size() - 2;
  EXPECT_EQ(c.positions[last].x, c.positions[0].x);
  EXPECT_EQ(c.positions[last + 1].z, c.positions[1].z);
  EXPECT_EQ(c.uvs[last].x, 1.f);
  EXPECT_THROW(makeCylinder(p0, p0, r), std::runtime_error);
  EXPECT_THROW(makeCylinder(p0, p1, 0.f), std::runtime_error);
}
