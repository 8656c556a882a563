// envgi_bench_gpu: the GPU renderer against the CPU on the same machine, as a table.
// Happy Buddha (bundled) and the 871k dragon (--dragon PATH, or ../shared/assets), 512^2,
// `path` with max_depth 8, a GGX conductor (alpha 0.15) in the Grace map, as the Mitsuba 3
// figure quoted in the GPU issue. Per device: milliseconds per 1-spp frame (median of
// --frames), M samples/s and M rays/s over a --spp run (default 64; the CPU runs --cpu-spp).
// Then SPPM on the bundled buddha scene at the same resolution: milliseconds a pass (median)
// and photons traced and splatted a second, with --sppm-photons a pass. And the photon-map pass
// (1M global photons stored, no caustic map): photons emitted a second, tracing only. And the
// grid integrator on the buddha scene (its own settings): ms a 1-spp frame once the grid is
// built, and what building it took. And the viewer orbiting the buddha (bench/ViewOrbit.h): the
// median time from a camera message to the first frame from that camera, path and grid.
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <string>
#include <vector>
#include <algorithm>
#include <chrono>

#include "accel/Bvh.h"
#include "accel/EmbreeAccel.h"
#include "gpu/CudaExecutor.h"
#include "gpu/GpuSceneFiles.h"
#include "render/CpuExecutor.h"
#include "render/PhotonShooter.h"
#include "render/Renderer.h"
#include "render/GridExecutor.h"
#include "render/SppmExecutor.h"
#include "scene/SceneLoader.h"
#include "support/FrameMesh.h"
#include "ViewOrbit.h"

using namespace envgi;

namespace {

struct Row {
  std::string scene, device;
  double frameMs = 0, msamples = 0, mrays = 0;
  int spp = 0;
};

double seconds(std::chrono::steady_clock::time_point t) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t).count();
}

Row measure(PassExecutor& ex, const std::string& scene, int W, int H, int frames, int spp) {
  Row r;
  r.scene = scene;
  r.device = ex.deviceName();
  Progress quiet(1, false);
  PassCounters c;
  ex.runPass(0, 1, quiet, &c);  // warm-up: first-touch, caches, kernel load
  std::vector<double> t;
  for (int i = 0; i < frames; ++i) {
    auto t0 = std::chrono::steady_clock::now();
    ex.runPass(1 + i, 2 + i, quiet, &c);
    t.push_back(seconds(t0));
  }
  std::sort(t.begin(), t.end());
  r.frameMs = 1e3 * t[t.size() / 2];
  PassCounters run;
  auto t0 = std::chrono::steady_clock::now();
  int base = 1 + frames;
  for (int s = 0; s < spp; s += 16) ex.runPass(base + s, base + std::min(spp, s + 16), quiet, &run);
  double sec = seconds(t0);
  r.spp = spp;
  r.msamples = double(W) * H * spp / sec / 1e6;
  r.mrays = double(run.rays) / sec / 1e6;
  return r;
}

struct SppmRow {
  std::string device;
  double passMs = 0, photonsPerSec = 0;
  int passes = 0;
};

SppmRow measureSppm(PassExecutor& ex, int passes) {
  SppmRow r;
  r.device = ex.deviceName();
  Progress quiet(1, false);
  PassCounters c;
  std::vector<double> t;
  for (int i = 0; i < passes; ++i) {
    auto t0 = std::chrono::steady_clock::now();
    ex.runPass(i, i + 1, quiet, &c);
    t.push_back(seconds(t0));
  }
  SppmStats st = dynamic_cast<SppmPassExecutor&>(ex).stats();
  std::sort(t.begin(), t.end());
  r.passMs = 1e3 * t[t.size() / 2];
  r.passes = passes;
  r.photonsPerSec = st.photonSeconds > 0 ? double(st.photonsShot) / st.photonSeconds : 0.0;
  return r;
}

}  // namespace

int main(int argc, char** argv) {
  std::string dragon;
  int res = 512, frames = 9, spp = 64, cpuSpp = 4, sppmPhotons = 1000000;
  bool cpu = true;
  for (int i = 1; i < argc; ++i) {
    std::string a = argv[i];
    auto next = [&] { return i + 1 < argc ? std::string(argv[++i]) : std::string(); };
    if (a == "--dragon") dragon = std::filesystem::absolute(next()).string();  // the scene XML resolves relative to itself
    else if (a == "--res") res = std::atoi(next().c_str());
    else if (a == "--frames") frames = std::atoi(next().c_str());
    else if (a == "--spp") spp = std::atoi(next().c_str());
    else if (a == "--cpu-spp") cpuSpp = std::atoi(next().c_str());
    else if (a == "--no-cpu") cpu = false;
    else if (a == "--sppm-photons") sppmPhotons = std::atoi(next().c_str());
    else {
      std::fprintf(stderr, "usage: envgi_bench_gpu [--dragon PLY] [--res N] [--frames N] [--spp N] [--cpu-spp N] [--no-cpu] [--sppm-photons N]\n");
      return 2;
    }
  }
  if (res <= 0 || frames <= 0 || spp <= 0 || cpuSpp <= 0 || sppmPhotons <= 0) {
    std::fprintf(stderr, "envgi_bench_gpu: --res, --frames, --spp, --cpu-spp and --sppm-photons must be positive\n");
    return 2;
  }
#ifdef ENVGI_ASSETS_DIR
  if (dragon.empty() && std::filesystem::exists(ENVGI_ASSETS_DIR "/meshes/dragon/dragon_vrip.ply"))
    dragon = ENVGI_ASSETS_DIR "/meshes/dragon/dragon_vrip.ply";
#endif
  std::vector<std::pair<std::string, std::string>> scenes = {{"buddha-100k", ""}};
  if (!dragon.empty()) scenes.push_back({"dragon-871k", dragon});
  std::string why;
  int gpus = gpu::deviceCount(&why);
  if (gpus == 0) std::printf("no CUDA device (%s): CPU figures only\n", why.c_str());
  if (gpus > 0) {
    gpu::KernelOccupancy o = gpu::pathKernelOccupancy(0);
    std::printf("path kernel: %d registers a thread, %d blocks of %d threads an SM\n", o.registers, o.blocksPerSM,
                o.threadsPerBlock);
  }
  std::vector<Row> rows;
  std::vector<SppmRow> sppmRows;
  std::vector<std::pair<std::string, double>> mapRows;  // device, M photons emitted a second
  struct ViewRow {
    std::string device, integrator;
    double ms, jpegKB;
  };
  std::vector<ViewRow> viewRows;
  try {
    for (auto& [name, mesh] : scenes) {
      Scene s;
      std::map<std::string, std::string> defs;
      if (!mesh.empty()) defs["mesh"] = mesh;
      loadScene(test::bundledScenesDir() + "/buddha.xml", defs, s);
      if (!mesh.empty()) test::frameLargestMesh(s);
      s.camera.width = s.camera.height = res;
      s.integrator.type = IntegratorType::Path;
      s.integrator.path.maxDepth = 8;
      s.integrator.env.strategy = "mis";
      for (Bsdf& b : s.bsdfs) {
        b = Bsdf{};
        b.type = BsdfType::RoughConductor;
        b.perfectMirror = true;
        b.alpha = 0.15f;
        b.specularReflectance = Color(1.f);
        b.twoSided = true;
      }
      s.finalize();
      RenderOptions o;
      o.spp = spp;
      KernelSettings k = kernelSettings(s, o);
      auto tb = std::chrono::steady_clock::now();
      Bvh bvh(s);
      std::printf("%s: %zu triangles, envgi BVH %.2f s (%.1f bytes a triangle)\n", name.c_str(), s.triangleCount(),
                  seconds(tb), double(bvh.stats().bytes()) / double(std::max<size_t>(1, bvh.stats().triangles)));
      if (gpus > 0) {
        auto ex = gpu::makeCudaExecutor(s, bvh, k, 0, false);
        rows.push_back(measure(*ex, name, res, res, frames, spp));
      }
      if (cpu) {
        EmbreeAccel accel(s);
        const SceneView& sc = s.view();
        SampleIntegrator<EmbreeTracer> integ{k.type, k.path, k.direct, &sc, EmbreeTracer{&accel}};
        CpuExecutor<decltype(integ)> ex(sc.camera, k.sequence, integ, 0, false, "cpu (Embree)");
        rows.push_back(measure(ex, name, res, res, std::min(frames, 3), cpuSpp));
        SampleIntegrator<BvhTracer> integB{k.type, k.path, k.direct, &sc, BvhTracer{bvh.view()}};
        CpuExecutor<decltype(integB)> exB(sc.camera, k.sequence, integB, 0, false, "cpu (envgi BVH)");
        rows.push_back(measure(exB, name, res, res, std::min(frames, 3), cpuSpp));
      }
    }
    Scene s;
    loadScene(test::bundledScenesDir() + "/buddha.xml", {}, s);
    s.camera.width = s.camera.height = res;
    s.integrator.type = IntegratorType::Sppm;
    s.integrator.sppm.photonCount = size_t(sppmPhotons);
    s.finalize();
    Bvh bvh(s);
    if (gpus > 0) {
      auto ex = gpu::makeCudaSppmExecutor(s, bvh, sppmParams(s), makePhotonEmitter(s), 0);
      sppmRows.push_back(measureSppm(*ex, frames));
    }
    if (cpu) {
      EmbreeAccel accel(s);
      SppmExecutor<EmbreeTracer> ex(s, EmbreeTracer{&accel}, sppmParams(s), 0);
      sppmRows.push_back(measureSppm(ex, 3));
    }
    EmbreeAccel accel(s);
    {
      Scene g;
      loadScene(test::bundledScenesDir() + "/buddha.xml", {}, g);
      g.camera.width = g.camera.height = res;
      g.integrator.type = IntegratorType::Grid;
      g.finalize();
      RenderOptions go;
      go.progress = false;
      SequenceAndSpp q = gridSequence(g, go);
      Bvh gb(g);
      if (gpus > 0) {
        auto t0 = std::chrono::steady_clock::now();
        auto ex = gpu::makeCudaGridExecutor(g, gb, gridExecutorSettings(g, go), q.sequence, 0, false);
        std::printf("grid on the GPU: photon maps and grid built in %.2f s\n", seconds(t0));
        rows.push_back(measure(*ex, "buddha (grid)", res, res, frames, spp));
      }
      if (cpu) {
        EmbreeAccel ga(g);
        GridExecutorSettings ge = gridExecutorSettings(g, go);
        ge.photons.tracer = makeCpuPhotonTracer(g, ga);
        auto t0 = std::chrono::steady_clock::now();
        GridExecutor<EmbreeTracer> ex(g, EmbreeTracer{&ga}, ge, q.sequence, 0, false, 16);
        std::printf("grid on the CPU: photon maps and grid built in %.2f s\n", seconds(t0));
        rows.push_back(measure(ex, "buddha (grid)", res, res, std::min(frames, 3), cpuSpp));
      }
    }
    PhotonShootSettings ps;
    ps.globalPhotons = 1000000;
    ps.causticPhotons = 0;
    ps.progress = false;
    for (int dev = gpus > 0 ? 0 : 1; dev < (cpu ? 2 : 1); ++dev) {
      if (dev == 0) ps.tracer = gpu::makeCudaPhotonTracer(s, bvh, 0, ps.maxDepth);
      else ps.tracer = makeCpuPhotonTracer(s, accel);
      PhotonMap g, c;
      PhotonShootStats st;
      shootPhotons(s, accel, ps, &g, &c, &st);
      mapRows.push_back({st.device, double(st.emittedGlobal) / st.traceSeconds / 1e6});
    }
    // The viewer orbiting the bundled buddha: camera message to the first frame from it.
    for (int dev = gpus > 0 ? 0 : 1; dev < (cpu ? 2 : 1); ++dev)
      for (const char* integ : {"path", "grid"}) {
        ViewOptions vo;
        vo.maxSpp = 1;
        if (dev == 0) vo.prepare = gpu::cudaPreparer(0);
        bench::ViewOrbit orbit(test::bundledScenesDir() + "/buddha.xml", res, integ, vo);
        std::vector<double> t;
        for (int i = 0; i < (dev == 0 ? 4 * frames : frames); ++i) t.push_back(orbit.moveAndWait());
        std::sort(t.begin(), t.end());
        viewRows.push_back({dev == 0 ? "cuda:0 (" + gpu::deviceName(0) + ")" : "cpu", integ, t[t.size() / 2],
                            double(orbit.lastJpegBytes()) / 1e3});
      }
  } catch (const std::exception& e) {
    std::fprintf(stderr, "envgi_bench_gpu: error: %s\n", e.what());
    return 1;
  }
  std::printf("\n%dx%d, path, max_depth 8, GGX conductor alpha 0.15, Grace map (grid rows: the grid integrator on "
              "the buddha scene as bundled)\n", res, res);
  std::printf("| scene | device | ms / 1-spp frame | spp run | M samples/s | M rays/s |\n|---|---|---|---|---|---|\n");
  for (const Row& r : rows)
    std::printf("| %s | %s | %.2f | %d | %.2f | %.1f |\n", r.scene.c_str(), r.device.c_str(), r.frameMs, r.spp,
                r.msamples, r.mrays);
  std::printf("\n%dx%d, sppm on buddha, %d photons a pass\n", res, res, sppmPhotons);
  std::printf("| device | ms / pass (median) | passes | M photons/s |\n|---|---|---|---|\n");
  for (const SppmRow& r : sppmRows)
    std::printf("| %s | %.1f | %d | %.2f |\n", r.device.c_str(), r.passMs, r.passes, r.photonsPerSec / 1e6);
  std::printf("\nphoton-map pass on buddha, 1M global photons stored\n| device | M photons emitted/s |\n|---|---|\n");
  for (auto& [dev, rate] : mapRows) std::printf("| %s | %.2f |\n", dev.c_str(), rate);
  std::printf("\nviewer orbiting buddha at %dx%d, 1 spp a camera: camera message to its first frame (render, "
              "tone map, JPEG), median\n| device | integrator | ms | JPEG kB |\n|---|---|---|---|\n", res, res);
  for (const ViewRow& r : viewRows)
    std::printf("| %s | %s | %.1f | %.1f |\n", r.device.c_str(), r.integrator.c_str(), r.ms, r.jpegKB);
  return 0;
}
