// A strict PLY reader. Assimp 5.2 (Debian 12) hangs on a binary PLY cut inside its header and
// aborts on a truncated ASCII one, so envgi reads PLY itself and checks every byte it reads.
#include <algorithm>
#include <bit>
#include <cstring>
#include <fstream>
#include <sstream>
#include <stdexcept>

#include "scene/TriangleMesh.h"

namespace envgi {

namespace {

enum class Fmt { Ascii, BinaryLE, BinaryBE };

struct Property {
  std::string name;
  std::string type;       // scalar type, or the item type of a list
  std::string countType;  // non-empty for lists
};

struct Element {
  std::string name;
  size_t count = 0;
  std::vector<Property> props;
};

int typeSize(const std::string& t, const std::string& path) {
  if (t == "char" || t == "uchar" || t == "int8" || t == "uint8") return 1;
  if (t == "short" || t == "ushort" || t == "int16" || t == "uint16") return 2;
  if (t == "int" || t == "uint" || t == "int32" || t == "uint32" || t == "float" || t == "float32") return 4;
  if (t == "double" || t == "float64") return 8;
  throw std::runtime_error("PLY file '" + path + "': unknown property type '" + t + "'");
}

class Cursor {
 public:
  Cursor(const std::string& data, size_t pos, Fmt fmt, const std::string& path)
      : d_(data), pos_(pos), fmt_(fmt), path_(path) {}

  double read(const std::string& type) {
    if (fmt_ == Fmt::Ascii) return readAscii();
    int n = typeSize(type, path_);
    if (pos_ + n > d_.size()) fail("unexpected end of file (truncated?)");
    unsigned char b[8];
    std::memcpy(b, d_.data() + pos_, n);
    pos_ += n;
    bool little = std::endian::native == std::endian::little;
    if ((fmt_ == Fmt::BinaryLE) != little) std::reverse(b, b + n);
    if (type == "char" || type == "int8") return double(int8_t(b[0]));
    if (type == "uchar" || type == "uint8") return double(b[0]);
    if (type == "short" || type == "int16") { int16_t v; std::memcpy(&v, b, 2); return v; }
    if (type == "ushort" || type == "uint16") { uint16_t v; std::memcpy(&v, b, 2); return v; }
    if (type == "int" || type == "int32") { int32_t v; std::memcpy(&v, b, 4); return v; }
    if (type == "uint" || type == "uint32") { uint32_t v; std::memcpy(&v, b, 4); return v; }
    if (type == "float" || type == "float32") { float v; std::memcpy(&v, b, 4); return v; }
    double v;
    std::memcpy(&v, b, 8);
    return v;
  }
  // A list's length, read as its count type; NaN, negative or absurd lengths are errors.
  size_t listLength(const std::string& countType) {
    double n = read(countType);
    if (!(n >= 0 && n <= 1e6)) fail("a list near byte " + std::to_string(pos_) + " has a bad length");
    return size_t(n);
  }
  size_t remaining() const { return d_.size() - pos_; }
  [[noreturn]] void fail(const std::string& what) const { throw std::runtime_error("PLY file '" + path_ + "': " + what); }

 private:
  double readAscii() {
    while (pos_ < d_.size() && std::isspace((unsigned char)d_[pos_])) ++pos_;
    if (pos_ >= d_.size()) fail("unexpected end of file (truncated?)");
    const char* start = d_.data() + pos_;
    char* end = nullptr;
    double v = std::strtod(start, &end);
    if (end == start) fail("expected a number near byte " + std::to_string(pos_));
    pos_ += size_t(end - start);
    return v;
  }
  const std::string& d_;
  size_t pos_;
  Fmt fmt_;
  const std::string& path_;
};

// A value read from the file, as the error should show it (9, 1e+300, nan).
std::string numberText(double v) {
  std::ostringstream o;
  o << v;
  return o.str();
}

}  // namespace

TriangleMesh loadPly(const std::string& path) {
  std::ifstream f(path, std::ios::binary);
  if (!f) throw std::runtime_error("cannot open PLY file '" + path + "'");
  std::string data((std::istreambuf_iterator<char>(f)), std::istreambuf_iterator<char>());
  auto fail = [&](const std::string& what) -> void { throw std::runtime_error("PLY file '" + path + "': " + what); };

  // Header: lines up to "end_header".
  size_t pos = 0;
  auto nextLine = [&](std::string& line) {
    if (pos >= data.size()) return false;
    size_t e = data.find('\n', pos);
    if (e == std::string::npos) return false;  // a header always ends in a newline
    line = data.substr(pos, e - pos);
    if (!line.empty() && line.back() == '\r') line.pop_back();
    pos = e + 1;
    return true;
  };
  std::string line;
  if (!nextLine(line) || line != "ply") fail("not a PLY file (missing 'ply' magic)");
  Fmt fmt = Fmt::Ascii;
  bool haveFormat = false, ended = false;
  std::vector<Element> elements;
  int lineNo = 1;
  while (nextLine(line)) {
    ++lineNo;
    std::istringstream ls(line);
    std::string kw;
    ls >> kw;
    if (kw.empty() || kw == "comment" || kw == "obj_info") continue;
    if (kw == "format") {
      std::string f2, ver;
      ls >> f2 >> ver;
      if (f2 == "ascii") fmt = Fmt::Ascii;
      else if (f2 == "binary_little_endian") fmt = Fmt::BinaryLE;
      else if (f2 == "binary_big_endian") fmt = Fmt::BinaryBE;
      else fail("unknown format '" + f2 + "' on header line " + std::to_string(lineNo));
      haveFormat = true;
    } else if (kw == "element") {
      Element e;
      long long count = -1;
      ls >> e.name >> count;
      if (e.name.empty() || count < 0) fail("bad element line " + std::to_string(lineNo) + ": '" + line + "'");
      e.count = size_t(count);
      elements.push_back(e);
    } else if (kw == "property") {
      if (elements.empty()) fail("property before any element on header line " + std::to_string(lineNo));
      Property p;
      std::string t;
      ls >> t;
      if (t == "list") {
        ls >> p.countType >> p.type >> p.name;
        typeSize(p.countType, path);
      } else {
        p.type = t;
        ls >> p.name;
      }
      typeSize(p.type, path);
      if (p.name.empty()) fail("property without a name on header line " + std::to_string(lineNo));
      elements.back().props.push_back(p);
    } else if (kw == "end_header") {
      ended = true;
      break;
    } else {
      fail("unexpected header keyword '" + kw + "' on line " + std::to_string(lineNo));
    }
  }
  if (!ended) fail("header has no 'end_header' (truncated?)");
  if (!haveFormat) fail("header has no 'format' line");

  TriangleMesh mesh;
  mesh.name = path;
  Cursor cur(data, pos, fmt, path);
  bool sawVertex = false, sawFace = false;
  for (const Element& e : elements) {
    // Every item takes at least a byte a property (a digit in ASCII), so the bytes left bound
    // the count before anything is allocated for it.
    size_t minBytes = 0;
    for (const Property& p : e.props)
      minBytes += fmt == Fmt::Ascii ? 1 : size_t(typeSize(p.countType.empty() ? p.type : p.countType, path));
    if (minBytes > 0 && e.count > cur.remaining() / minBytes)
      fail("element '" + e.name + "' declares " + std::to_string(e.count) + " items, more than the " +
           std::to_string(cur.remaining()) + " bytes after the header hold (truncated?)");
    if (e.name == "vertex") {
      sawVertex = true;
      int ix = -1, iy = -1, iz = -1, inx = -1, iny = -1, inz = -1, iu = -1, iv = -1;
      for (size_t k = 0; k < e.props.size(); ++k) {
        const std::string& n = e.props[k].name;
        if (!e.props[k].countType.empty()) continue;
        if (n == "x") ix = int(k);
        else if (n == "y") iy = int(k);
        else if (n == "z") iz = int(k);
        else if (n == "nx") inx = int(k);
        else if (n == "ny") iny = int(k);
        else if (n == "nz") inz = int(k);
        else if (n == "u" || n == "s" || n == "texture_u" || n == "texture_s") iu = int(k);
        else if (n == "v" || n == "t" || n == "texture_v" || n == "texture_t") iv = int(k);
      }
      if (ix < 0 || iy < 0 || iz < 0) fail("vertex element lacks x, y or z");
      bool hasN = inx >= 0 && iny >= 0 && inz >= 0, hasUV = iu >= 0 && iv >= 0;
      mesh.positions.resize(e.count);
      if (hasN) mesh.normals.resize(e.count);
      if (hasUV) mesh.uvs.resize(e.count);
      std::vector<double> vals(e.props.size());
      for (size_t i = 0; i < e.count; ++i) {
        for (size_t k = 0; k < e.props.size(); ++k) {
          const Property& p = e.props[k];
          if (!p.countType.empty()) {
            size_t n = cur.listLength(p.countType);
            for (size_t j = 0; j < n; ++j) cur.read(p.type);
            vals[k] = 0.0;
          } else {
            vals[k] = cur.read(p.type);
          }
        }
        mesh.positions[i] = Vec3f(float(vals[ix]), float(vals[iy]), float(vals[iz]));
        if (hasN) mesh.normals[i] = Vec3f(float(vals[inx]), float(vals[iny]), float(vals[inz]));
        if (hasUV) mesh.uvs[i] = Vec2f(float(vals[iu]), float(vals[iv]));
      }
    } else if (e.name == "face") {
      sawFace = true;
      int il = -1;
      for (size_t k = 0; k < e.props.size(); ++k)
        if (!e.props[k].countType.empty() && (e.props[k].name == "vertex_indices" || e.props[k].name == "vertex_index"))
          il = int(k);
      if (il < 0) fail("face element lacks a 'vertex_indices' list");
      mesh.indices.reserve(e.count * 3);
      std::vector<uint32_t> poly;
      for (size_t i = 0; i < e.count; ++i) {
        for (size_t k = 0; k < e.props.size(); ++k) {
          const Property& p = e.props[k];
          if (p.countType.empty()) {
            cur.read(p.type);
            continue;
          }
          double n = cur.read(p.countType);
          if (!(n >= 0 && n <= 1e6)) fail("face " + std::to_string(i) + " has a bad vertex count");
          poly.clear();
          for (size_t j = 0; j < size_t(n); ++j) {
            double idx = cur.read(p.type);
            if (!(idx >= 0 && idx < double(mesh.positions.size())))
              fail("face " + std::to_string(i) + " refers to vertex " + numberText(idx) + " of " +
                   std::to_string(mesh.positions.size()));
            poly.push_back(uint32_t(idx));
          }
          if (int(k) != il) continue;
          if (poly.size() < 3) fail("face " + std::to_string(i) + " has fewer than 3 vertices");
          for (size_t j = 1; j + 1 < poly.size(); ++j) {
            mesh.indices.push_back(poly[0]);
            mesh.indices.push_back(poly[j]);
            mesh.indices.push_back(poly[j + 1]);
          }
        }
      }
    } else {
      // Other elements (edges, materials) are skipped, but must still be read past; one
      // without properties takes no bytes.
      if (e.props.empty()) continue;
      for (size_t i = 0; i < e.count; ++i)
        for (const Property& p : e.props) {
          if (p.countType.empty()) {
            cur.read(p.type);
          } else {
            size_t n = cur.listLength(p.countType);
            for (size_t j = 0; j < n; ++j) cur.read(p.type);
          }
        }
    }
  }
  if (!sawVertex) fail("no vertex element");
  if (!sawFace) fail("no face element");
  mesh.validate();
  return mesh;
}

}  // namespace envgi
