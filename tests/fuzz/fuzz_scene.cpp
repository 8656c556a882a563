// libFuzzer target: scene XML (loadScene), then a render of what loaded, cut down to at most
// 16x16 pixels, 1 sample, depth 8 and a few thousand photons so that every integrator runs in
// milliseconds. Beside the input lie a small PLY, OBJ, HDR map and square HDR probe (fuzz-m.ply,
// fuzz-m.obj, fuzz-e.hdr, fuzz-p.hdr, in the dictionary), so that shapes from files and the
// envmap emitter, lat-long or probe, are reached through the XML. The rendered image must be finite: the renderer drops non-finite samples.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cctype>
#include <filesystem>
#include <regex>
#include <fstream>
#include <stdexcept>

#include "fuzz/FuzzInput.h"
#include "image/Image.h"
#include "render/Renderer.h"
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
  envgi::Image probe(8, 8);  // square: a light probe for the envmap's layout
  for (size_t i = 0; i < probe.rgb.size(); ++i) probe.rgb[i] = float(i % 5) * 0.3f;
  envgi::saveImage(probe, (dir / "fuzz-p.hdr").string());
}

// Every number in the text between 1e-3 and 1e4 in magnitude (or 0), and no inf or nan: a scene
// whose samples should all be finite.
bool moderateNumbers(const std::string& text) {
  std::string lower = text;
  for (char& c : lower) c = char(std::tolower((unsigned char)c));
  if (lower.find("inf") != std::string::npos || lower.find("nan") != std::string::npos) return false;
  static const std::regex number(R"([-+]?(\d+\.?\d*|\.\d+)([eE][-+]?\d+)?)");
  for (auto it = std::sregex_iterator(text.begin(), text.end(), number); it != std::sregex_iterator(); ++it) {
    double v = std::fabs(std::strtod(it->str().c_str(), nullptr));
    if (v != 0.0 && (v < 1e-3 || v > 1e4)) return false;
  }
  return true;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  std::string path = envgi::fuzz::writeInput(data, size, ".xml");
  static const bool assets = (writeAssets(std::filesystem::path(path).parent_path()), true);
  (void)assets;
  envgi::Scene scene;
  try {
    envgi::loadScene(path, {}, scene);
  } catch (const std::runtime_error&) {
    return 0;
  }
  scene.camera.width = std::min(scene.camera.width, 16);
  scene.camera.height = std::min(scene.camera.height, 16);
  envgi::IntegratorSettings& in = scene.integrator;
  auto depth = [](int& d) { d = d < 0 || d > 8 ? 8 : d; };
  depth(in.path.maxDepth);
  depth(in.photon.maxDepth);
  depth(in.sppm.maxDepth);
  depth(in.grid.maxDepth);
  in.direct.emitterSamples = std::min(in.direct.emitterSamples, 4);
  in.direct.bsdfSamples = std::min(in.direct.bsdfSamples, 4);
  in.photon.globalPhotons = std::min<size_t>(in.photon.globalPhotons, 2000);
  in.photon.causticPhotons = std::min<size_t>(in.photon.causticPhotons, 2000);
  in.photon.gatherSamples = std::min(in.photon.gatherSamples, 2);
  in.sppm.passes = 1;
  in.sppm.photonCount = std::min<size_t>(in.sppm.photonCount, 2000);
  in.grid.resolution = std::min(in.grid.resolution, 4);
  in.grid.gatherRays = std::min(in.grid.gatherRays, 4);
  in.grid.maxGatherRays = std::min(in.grid.maxGatherRays, 8);
  in.grid.refineRays = std::min(in.grid.refineRays, 4);
  in.grid.globalPhotons = std::min<size_t>(in.grid.globalPhotons, 2000);
  in.grid.causticPhotons = std::min<size_t>(in.grid.causticPhotons, 500);
  in.env.pointCount = std::min(in.env.pointCount, 16);
  // The kernels read the camera from the scene's view, which loadScene's finalize() made: without
  // this, a scene with no film rendered 768 x 576 pixels (a 40 s timeout under the sanitizers).
  scene.finalize();
  envgi::RenderOptions opts;
  opts.spp = 1;
  opts.threads = 1;
  opts.progress = false;
  opts.checkpointSeconds = 0.0;
  try {
    envgi::EmbreeAccel accel(scene);
    envgi::RenderStats stats;
    envgi::Image img = envgi::render(scene, accel, opts, &stats);
    if (envgi::nonFiniteValues(img) > 0) {
      std::fprintf(stderr, "fuzz_scene: a non-finite pixel in the render\n");
      std::abort();
    }
    // The renderer drops NaN and infinite samples; a scene of moderate numbers should make none.
    if (stats.nonFiniteSamples > 0 && moderateNumbers(std::string(reinterpret_cast<const char*>(data), size))) {
      std::fprintf(stderr, "fuzz_scene: %llu non-finite samples from a scene of moderate numbers\n",
                   (unsigned long long)stats.nonFiniteSamples);
      std::abort();
    }
  } catch (const std::runtime_error&) {
  }
  return 0;
}
