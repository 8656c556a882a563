// Instancing against copies: the same N placements of the bundled Buddha (100k triangles) in a
// grid on a floor, once as a shapegroup placed by N instances and once as N shapes written out
// with the same to_world. Per variant: loading the XML (meshes read, placed, normals made) and
// building Embree's BVH, timed together, with the memory they leave as counters: the scene's
// geometry (Scene::geometryBytes) and Embree's (its memory monitor), in MB, and the triangles
// placed. Then a 64^2, 4 spp path render of each, whose rays/s shows what two levels cost.
// Run: build/bin/envgi_bench_instances --benchmark_repetitions=3 --benchmark_report_aggregates_only=true
#include <benchmark/benchmark.h>

#include <filesystem>
#include <fstream>
#include <string>

#include "accel/EmbreeAccel.h"
#include "render/Renderer.h"
#include "scene/SceneLoader.h"

using namespace envgi;

namespace {

// The scene file for n placements (n a square), instanced or written out; returns its path.
std::string sceneFile(int n, bool instanced) {
  const std::string src = ENVGI_SOURCE_DIR;
  const std::string mesh = src + "/scenes/meshes/happy_buddha_100k.ply";
  std::string xml = R"(<scene version="3.0.0">
  <integrator type="path"><integer name="max_depth" value="4"/></integrator>
  <sensor type="perspective"><float name="fov" value="40"/>
    <transform name="to_world"><lookat origin="0,6,14" target="0,0,0"/></transform>
    <sampler type="sobol"><integer name="sample_count" value="4"/></sampler>
    <film type="hdrfilm"><integer name="width" value="64"/><integer name="height" value="64"/></film></sensor>
  <emitter type="envmap"><string name="filename" value=")" + src + R"(/scenes/envmaps/grace_latlong.hdr"/><float name="scale" value="25"/></emitter>
  <shape type="rectangle"><transform name="to_world"><scale value="12"/><rotate x="1" angle="-90"/><translate y="-0.6"/></transform></shape>
)";
  const std::string shape = R"(<shape type="ply"><string name="filename" value=")" + mesh + R"("/>
    <bsdf type="roughplastic"><rgb name="diffuse_reflectance" value="0.55, 0.45, 0.3"/><float name="alpha" value="0.12"/></bsdf>)";
  if (instanced) xml += R"(<shape type="shapegroup" id="b">)" + shape + "</shape></shape>\n";
  int side = 1;
  while (side * side < n) ++side;
  for (int k = 0; k < n; ++k) {
    int i = k / side, j = k % side;
    const std::string xf = "<transform name=\"to_world\"><rotate y=\"1\" angle=\"" + std::to_string((i * 37 + j * 11) % 360) +
                           "\"/><translate x=\"" + std::to_string((i - (side - 1) * 0.5) * 1.1) + "\" z=\"" +
                           std::to_string((j - (side - 1) * 0.5) * 1.1) + "\"/></transform>";
    xml += instanced ? "<shape type=\"instance\"><ref id=\"b\"/>" + xf + "</shape>\n" : shape + xf + "</shape>\n";
  }
  xml += "</scene>\n";
  const std::string path = (std::filesystem::temp_directory_path() /
                            ("envgi-bench-instances-" + std::to_string(n) + (instanced ? "-i" : "-c") + ".xml"))
                               .string();
  std::ofstream(path) << xml;
  return path;
}

// Arguments: placements, instanced (1) or written out (0).
void BM_LoadAndBuild(benchmark::State& state) {
  const int n = int(state.range(0));
  const bool instanced = state.range(1) != 0;
  const std::string path = sceneFile(n, instanced);
  double geometry = 0.0, embree = 0.0, triangles = 0.0;
  for (auto _ : state) {
    Scene scene;
    loadScene(path, {}, scene);
    EmbreeAccel accel(scene);
    geometry = double(scene.geometryBytes()) / 1e6;
    embree = double(accel.bytes()) / 1e6;
    triangles = double(scene.triangleCount());
    benchmark::DoNotOptimize(accel.handle());
  }
  state.counters["geometry_MB"] = geometry;
  state.counters["embree_MB"] = embree;
  state.counters["triangles"] = triangles;
}
BENCHMARK(BM_LoadAndBuild)->Args({25, 0})->Args({25, 1})->Args({100, 0})->Args({100, 1})->Unit(benchmark::kMillisecond)->UseRealTime();

void BM_Render(benchmark::State& state) {
  const int n = int(state.range(0));
  Scene scene;
  loadScene(sceneFile(n, state.range(1) != 0), {}, scene);
  EmbreeAccel accel(scene);
  uint64_t rays = 0;
  for (auto _ : state) {
    RenderOptions o;
    o.progress = false;
    o.threads = 1;
    RenderStats st;
    Image img = render(scene, accel, o, &st);
    benchmark::DoNotOptimize(img.rgb.data());
    rays += st.rays;
  }
  state.counters["rays/s"] = benchmark::Counter(double(rays), benchmark::Counter::kIsRate);
}
BENCHMARK(BM_Render)->Args({25, 0})->Args({25, 1})->Unit(benchmark::kMillisecond)->UseRealTime();

}  // namespace

BENCHMARK_MAIN();
