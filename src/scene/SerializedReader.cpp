// Mitsuba's .serialized meshes: a header, then a zlib stream per mesh, and a dictionary of the
// meshes' offsets at the end of the file (Mitsuba's format description, versions 3 and 4).
#include <fmt/format.h>
#include <zlib.h>

#include <cstring>
#include <fstream>
#include <stdexcept>

#include "scene/TriangleMesh.h"

namespace envgi {

namespace {

constexpr uint16_t kSerializedMagic = 0x041C;
enum SerializedFlags : uint32_t {
  kHasNormals = 0x0001,
  kHasTexcoords = 0x0002,
  kHasColors = 0x0008,
  kFaceNormals = 0x0010,
  kDoublePrecision = 0x2000,
};

// Reads a zlib stream a requested number of bytes at a time, so that a count in the file that
// the data does not back fails as truncated before anything that large is allocated.
class Inflater {
 public:
  Inflater(const std::string& path, const unsigned char* data, size_t size) : path_(path) {
    std::memset(&z_, 0, sizeof(z_));
    if (inflateInit(&z_) != Z_OK) throw std::runtime_error(path_ + ": zlib could not start");
    z_.next_in = const_cast<unsigned char*>(data);
    z_.avail_in = uInt(std::min<size_t>(size, 0x7fffffffu));
  }
  ~Inflater() { inflateEnd(&z_); }
  Inflater(const Inflater&) = delete;
  Inflater& operator=(const Inflater&) = delete;

  void read(void* dst, size_t n) {
    auto* out = static_cast<unsigned char*>(dst);
    while (n > 0) {
      size_t chunk = std::min<size_t>(n, 1u << 30);
      z_.next_out = out;
      z_.avail_out = uInt(chunk);
      while (z_.avail_out > 0) {
        int r = inflate(&z_, Z_NO_FLUSH);
        if (r == Z_STREAM_END && z_.avail_out > 0) throw std::runtime_error(path_ + ": the mesh data ends early");
        if (r != Z_OK && r != Z_STREAM_END)
          throw std::runtime_error(path_ + ": corrupt compressed mesh data (" + (z_.msg ? z_.msg : "zlib error") + ")");
        if (r == Z_OK && z_.avail_in == 0 && z_.avail_out > 0) throw std::runtime_error(path_ + ": the file is truncated");
      }
      out += chunk;
      n -= chunk;
    }
  }
  template <class T>
  T value() {
    T v;
    read(&v, sizeof(T));
    return v;
  }
  // count values of T, in chunks that grow the array only as the data arrives (see above).
  template <class T>
  std::vector<T> array(uint64_t count) {
    constexpr uint64_t kChunk = 1u << 22;
    std::vector<T> out;
    for (uint64_t done = 0; done < count;) {
      const uint64_t n = std::min(kChunk, count - done);
      out.resize(out.size() + size_t(n));
      read(out.data() + done, size_t(n) * sizeof(T));
      done += n;
    }
    return out;
  }
  // count values stored as double or float, as floats.
  std::vector<float> floats(uint64_t count, bool dbl) {
    if (!dbl) return array<float>(count);
    std::vector<double> d = array<double>(count);
    return std::vector<float>(d.begin(), d.end());
  }

 private:
  std::string path_;
  z_stream z_;
};

template <class T>
T readAt(const std::vector<unsigned char>& bytes, size_t at) {
  T v;
  std::memcpy(&v, bytes.data() + at, sizeof(T));
  return v;
}

}  // namespace

TriangleMesh loadSerialized(const std::string& path, int shapeIndex, bool* faceNormals) {
  static_assert(sizeof(float) == 4 && sizeof(double) == 8, "IEEE floats");
  std::ifstream f(path, std::ios::binary);
  if (!f) throw std::runtime_error("cannot open mesh file '" + path + "'");
  std::vector<unsigned char> bytes((std::istreambuf_iterator<char>(f)), std::istreambuf_iterator<char>());
  if (bytes.size() < 4 || readAt<uint16_t>(bytes, 0) != kSerializedMagic)
    throw std::runtime_error(path + ": not a Mitsuba .serialized mesh (no 0x041C header)");
  const uint16_t version = readAt<uint16_t>(bytes, 2);
  if (version != 3 && version != 4)
    throw std::runtime_error(fmt::format("{}: .serialized version {} (envgi reads 3 and 4)", path, version));
  if (shapeIndex < 0) throw std::runtime_error(path + ": shape_index must not be negative");
  size_t offset = 0;
  if (shapeIndex > 0) {
    // The dictionary at the end: each mesh's offset (uint64 in version 4, uint32 in 3), then
    // the mesh count.
    if (bytes.size() < 8) throw std::runtime_error(path + ": no dictionary of meshes at the end");
    const uint32_t count = readAt<uint32_t>(bytes, bytes.size() - 4);
    if (uint32_t(shapeIndex) >= count)
      throw std::runtime_error(fmt::format("{}: shape_index {} is out of range (the file holds {} meshes)", path,
                                           shapeIndex, count));
    const size_t entry = version == 4 ? 8 : 4;
    if (size_t(count) * entry + 4 > bytes.size()) throw std::runtime_error(path + ": corrupt dictionary of meshes");
    const size_t at = bytes.size() - 4 - size_t(count - uint32_t(shapeIndex)) * entry;
    offset = version == 4 ? size_t(readAt<uint64_t>(bytes, at)) : size_t(readAt<uint32_t>(bytes, at));
    // Compared as offset > size - 4 (size is at least 8 here): offset + 4 wraps for an offset near 2^64.
    if (offset > bytes.size() - 4 || readAt<uint16_t>(bytes, offset) != kSerializedMagic)
      throw std::runtime_error(fmt::format("{}: mesh {} does not start with the 0x041C header", path, shapeIndex));
  }
  Inflater z(path, bytes.data() + offset + 4, bytes.size() - offset - 4);
  const uint32_t flags = z.value<uint32_t>();
  TriangleMesh m;
  if (version == 4)
    for (char c = z.value<char>(); c != 0; c = z.value<char>()) m.name += c;
  const uint64_t vertices = z.value<uint64_t>(), triangles = z.value<uint64_t>();
  if (vertices > 0xFFFFFFFFull || triangles > 0x7FFFFFFFull)
    throw std::runtime_error(fmt::format("{}: {} vertices and {} triangles are more than envgi indexes", path, vertices,
                                         triangles));
  const bool dbl = (flags & kDoublePrecision) != 0;
  auto vec3s = [&](std::vector<Vec3f>* out) {
    std::vector<float> v = z.floats(3 * vertices, dbl);
    out->reserve(size_t(vertices));
    for (size_t i = 0; i < v.size(); i += 3) out->emplace_back(v[i], v[i + 1], v[i + 2]);
  };
  vec3s(&m.positions);
  if (flags & kHasNormals) vec3s(&m.normals);
  if (flags & kHasTexcoords) {
    std::vector<float> t = z.floats(2 * vertices, dbl);
    m.uvs.reserve(size_t(vertices));
    for (size_t i = 0; i < t.size(); i += 2) m.uvs.emplace_back(t[i], t[i + 1]);
  }
  if (flags & kHasColors) z.floats(3 * vertices, dbl);  // vertex colours: read past, as Mitsuba does
  // Indices are 32-bit (64-bit only past 2^32 vertices, which the check above refuses).
  m.indices = z.array<uint32_t>(3 * triangles);
  m.validate();
  if (faceNormals) *faceNormals = (flags & kFaceNormals) != 0;
  return m;
}

}  // namespace envgi
