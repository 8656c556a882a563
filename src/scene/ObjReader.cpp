#include <fmt/format.h>
#include <tiny_obj_loader.h>

#include <algorithm>
#include <charconv>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <map>
#include <sstream>
#include <stdexcept>

#include "scene/TriangleMesh.h"

namespace envgi {

namespace {

// tinyobjloader reads a number it cannot parse ("abc", "nan", "1e999") and a missing coordinate
// as 0, so a garbled vertex line moved the vertex to the origin without a word; and it drops a
// face of fewer than three vertices. Those lines are checked here first: v, vn and vt take
// finite numbers, at least three for v and vn and one for vt, and f at least three vertices.
void checkObjLines(const std::string& path, const std::string& text) {
  std::istringstream f(text);
  std::string line;
  for (size_t lineNo = 1; std::getline(f, line); ++lineNo) {
    size_t k = line.find_first_not_of(" \t");
    if (k == std::string::npos) continue;
    const size_t tagEnd = std::min(line.find_first_of(" \t\r", k), line.size());
    const std::string tag = line.substr(k, tagEnd - k);
    if (tag != "v" && tag != "vn" && tag != "vt" && tag != "f") continue;
    auto fail = [&](const std::string& what) {
      throw std::runtime_error(fmt::format("OBJ file '{}': line {}: {}", path, lineNo, what));
    };
    int count = 0;
    for (k = tagEnd;; ++count) {
      k = line.find_first_not_of(" \t\r", k);
      if (k == std::string::npos || line[k] == '#') break;
      const size_t end = std::min(line.find_first_of(" \t\r", k), line.size());
      if (tag != "f") {
        float v = 0.f;
        const size_t from = line[k] == '+' && k + 1 < end && line[k + 1] != '-' ? k + 1 : k;  // from_chars takes no '+'
        auto [ptr, ec] = std::from_chars(line.data() + from, line.data() + end, v);
        if (ec != std::errc() || ptr != line.data() + end || !std::isfinite(v))
          fail(fmt::format("'{}' is not a finite number", line.substr(k, end - k)));
      }
      k = end;
    }
    if (tag == "f" && count < 3) fail(fmt::format("a face needs 3 vertices or more, it has {}", count));
    const int needed = tag == "vt" ? 1 : 3;
    if (tag != "f" && count < needed)
      fail(fmt::format("{} needs {} coordinate{}, it has {}", tag, needed, needed > 1 ? "s" : "", count));
  }
}

}  // namespace

TriangleMesh loadObj(const std::string& path) {
  std::ifstream f(path, std::ios::binary);
  if (!std::filesystem::is_regular_file(path) || !f) throw std::runtime_error("cannot open OBJ file '" + path + "'");
  // Read once: checked, then parsed from memory (envgi takes its materials from the scene, so
  // no .mtl file is read).
  const std::string text((std::istreambuf_iterator<char>(f)), std::istreambuf_iterator<char>());
  checkObjLines(path, text);
  tinyobj::ObjReaderConfig cfg;
  cfg.triangulate = true;
  cfg.vertex_color = false;
  tinyobj::ObjReader reader;
  if (!reader.ParseFromString(text, "", cfg)) {
    std::string err = reader.Error();
    while (!err.empty() && (err.back() == '\n' || err.back() == '\r')) err.pop_back();
    throw std::runtime_error("OBJ file '" + path + "': " + (err.empty() ? "cannot parse" : err));
  }
  const tinyobj::attrib_t& a = reader.GetAttrib();
  TriangleMesh mesh;
  mesh.name = path;
  bool allNormals = true, allUVs = true;
  for (const auto& s : reader.GetShapes())
    for (const auto& idx : s.mesh.indices) {
      allNormals = allNormals && idx.normal_index >= 0;
      allUVs = allUVs && idx.texcoord_index >= 0;
    }
  // OBJ indexes positions, normals and uvs separately: one output vertex per distinct triple.
  std::map<std::tuple<int, int, int>, uint32_t> remap;
  auto vertex = [&](const tinyobj::index_t& idx) -> uint32_t {
    int n = allNormals ? idx.normal_index : -1, t = allUVs ? idx.texcoord_index : -1;
    auto key = std::make_tuple(idx.vertex_index, n, t);
    auto it = remap.find(key);
    if (it != remap.end()) return it->second;
    // tinyobjloader resolves negative (relative) indices but leaves the range to the caller.
    auto outside = [](int i, int k, size_t n) { return i < 0 || size_t(i) >= n / k; };
    if (outside(idx.vertex_index, 3, a.vertices.size()))
      throw std::runtime_error("OBJ file '" + path + "': vertex index out of range");
    if (n >= 0 && outside(n, 3, a.normals.size()))
      throw std::runtime_error("OBJ file '" + path + "': normal index out of range");
    if (t >= 0 && outside(t, 2, a.texcoords.size()))
      throw std::runtime_error("OBJ file '" + path + "': texture coordinate index out of range");
    uint32_t id = uint32_t(mesh.positions.size());
    mesh.positions.push_back({a.vertices[3 * idx.vertex_index], a.vertices[3 * idx.vertex_index + 1],
                              a.vertices[3 * idx.vertex_index + 2]});
    if (n >= 0) mesh.normals.push_back({a.normals[3 * n], a.normals[3 * n + 1], a.normals[3 * n + 2]});
    if (t >= 0) mesh.uvs.push_back({a.texcoords[2 * t], a.texcoords[2 * t + 1]});
    remap.emplace(key, id);
    return id;
  };
  for (const auto& s : reader.GetShapes())
    for (const auto& idx : s.mesh.indices) mesh.indices.push_back(vertex(idx));
  if (mesh.indices.empty()) throw std::runtime_error("OBJ file '" + path + "' has no faces");
  mesh.validate();
  return mesh;
}

}  // namespace envgi
