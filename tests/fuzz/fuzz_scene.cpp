// libFuzzer target: scene XML (loadScene), with the defaults a render would use. Beside the
// input lie a small PLY, OBJ and HDR map (fuzz-m.ply, fuzz-m.obj, fuzz-e.hdr, in the
// dictionary), so that shapes from files and the envmap emitter are reached through the XML.
#include <filesystem>
#include <fstream>
#include <stdexcept>

#include "fuzz/FuzzInput.h"
#include "image/Image.h"
#include "scene/SceneLoader.h"

namespace {

void writeAssets(const std::filesystem::path& dir) {
  std::ofstream(dir / "fuzz-m.ply") << "ply\nformat ascii 1.0\nelement vertex 4\nproperty float x\nproperty float y\n"
                                       "property float z\nelement face 1\nproperty list uchar int vertex_indices\n"
                                       "end_header\n0 0 0\n1 0 0\n1 1 0\n0 1 0\n4 0 1 2 3\n";
  std::ofstream(dir / "fuzz-m.obj") << "v 0 0 0\nv 1 0 0\nv 1 1 0\nvt 0 0\nvt 1 0\nvn 0 0 1\nf 1/1/1 2/2/1 3/1/1\n";
  envgi::Image map(16, 8);
  for (size_t i = 0; i < map.rgb.size(); ++i) map.rgb[i] = float(i % 7) * 0.25f;
  envgi::saveImage(map, (dir / "fuzz-e.hdr").string());
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  std::string path = envgi::fuzz::writeInput(data, size, ".xml");
  static const bool assets = (writeAssets(std::filesystem::path(path).parent_path()), true);
  (void)assets;
  try {
    envgi::Scene scene;
    envgi::loadScene(path, {}, scene);
  } catch (const std::runtime_error&) {
  }
  return 0;
}
