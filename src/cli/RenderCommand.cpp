// `envgi render SCENE.xml -o OUT.exr`: the CPU renderer from the command line.
#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include <atomic>
#include <chrono>
#include <csignal>
#include <filesystem>
#include <memory>
#include <stdexcept>

#include "accel/EmbreeAccel.h"
#include "cli/Commands.h"
#include "render/Renderer.h"
#include "scene/SceneLoader.h"

namespace envgi::cli {

namespace {

std::atomic<bool> g_cancel{false};
extern "C" void onInterrupt(int) { g_cancel.store(true); }

struct RenderArgs {
  std::string scene, output;
  int spp = -1, threads = 0;
  std::string integrator, strategy;
  std::vector<std::string> defines;
  long long seed = -1;
  bool png = false, noProgress = false;
  float exposure = 0.f;
  bool aces = false;
  double checkpoint = 60.0;
};

void runRender(const RenderArgs& a) {
  namespace fs = std::filesystem;
  std::string ext = fs::path(a.output).extension().string();
  if (ext != ".exr" && ext != ".pfm" && ext != ".hdr" && ext != ".png")
    throw std::runtime_error("output '" + a.output + "' must end in .exr, .pfm, .hdr or .png");
  auto t0 = std::chrono::steady_clock::now();
  Scene scene;
  loadScene(a.scene, parseDefines(a.defines), scene);
  if (!a.integrator.empty()) {
    if (a.integrator != "path" && a.integrator != "direct" && a.integrator != "photon" && a.integrator != "sppm")
      throw std::runtime_error("unknown integrator '" + a.integrator + "' (path, direct, photon, sppm)");
    scene.integrator.type = a.integrator;
  }
  if (!a.strategy.empty()) {
    parseStrategyName(a.strategy == "mis" || a.strategy == "bsdf" ? "importance" : a.strategy);
    scene.integrator.strategy = a.strategy;
  }
  if (a.seed >= 0) scene.sampler.seed = uint32_t(a.seed);
  scene.finalize();
  double loadSeconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  spdlog::info("scene {}: {} triangles, {} spheres, {} area-light primitives{}, {:.1f} MB of geometry, loaded in {:.2f} s",
               a.scene, scene.triangleCount(), scene.spheres.size(), scene.lightCount(),
               scene.env ? ", environment map" : "", scene.geometryBytes() / 1e6, loadSeconds);
  auto t1 = std::chrono::steady_clock::now();
  EmbreeAccel accel(scene);
  spdlog::info("Embree BVH built in {:.2f} s",
               std::chrono::duration<double>(std::chrono::steady_clock::now() - t1).count());

  SaveOptions so;
  so.exposure = a.exposure;
  so.toneMap = a.aces ? ToneMap::Aces : ToneMap::Clamp;
  std::string pngPath = fs::path(a.output).replace_extension(".png").string();
  auto write = [&](const Image& img) {
    saveImage(img, a.output, so);
    if (a.png && ext != ".png") saveImage(img, pngPath, so);
  };

  RenderOptions ro;
  ro.spp = a.spp;
  ro.threads = a.threads;
  ro.progress = !a.noProgress;
  ro.checkpointSeconds = a.checkpoint;
  ro.checkpoint = [&](const Image& img, int done) {
    write(img);
    spdlog::info("checkpoint: {} spp written to {}", done, a.output);
  };
  ro.cancel = &g_cancel;
  std::signal(SIGINT, onInterrupt);
  std::signal(SIGTERM, onInterrupt);
  RenderStats st;
  const IntegratorSettings& is = scene.integrator;
  spdlog::info("rendering {}x{} with '{}' (strategy {}), {} spp, {} sampler", scene.camera.width, scene.camera.height,
               is.type, is.strategy, a.spp > 0 ? a.spp : scene.sampler.sampleCount,
               scene.sampler.type == SamplerType::Independent ? "independent"
               : scene.sampler.type == SamplerType::Stratified ? "stratified" : "sobol");
  Image img = render(scene, accel, ro, &st);
  std::signal(SIGINT, SIG_DFL);
  std::signal(SIGTERM, SIG_DFL);
  write(img);
  if (st.cancelled) spdlog::warn("interrupted: wrote the {} samples per pixel finished so far", st.sppDone);
  spdlog::info("done in {:.2f} s: {} spp, {:.3g} rays, {:.3g} Mrays/s", st.seconds, st.sppDone, double(st.rays),
               st.raysPerSecond() / 1e6);
  spdlog::info("wrote {}{}", fs::absolute(a.output).string(),
               a.png && ext != ".png" ? " and " + fs::absolute(pngPath).string() : "");
}

}  // namespace

std::map<std::string, std::string> parseDefines(const std::vector<std::string>& ds) {
  std::map<std::string, std::string> out;
  for (const std::string& d : ds) {
    size_t eq = d.find('=');
    if (eq == std::string::npos || eq == 0) throw std::runtime_error("-D expects name=value, got '" + d + "'");
    out[d.substr(0, eq)] = d.substr(eq + 1);
  }
  return out;
}

void addRenderCommand(CLI::App& app) {
  auto a = std::make_shared<RenderArgs>();
  CLI::App* c = app.add_subcommand("render", "Render a scene (Mitsuba 3 XML subset) to an image");
  c->add_option("scene", a->scene, "Scene file (.xml)")->required()->check(CLI::ExistingFile);
  c->add_option("-o,--output", a->output, "Output image (.exr, .pfm, .hdr or .png)")->required();
  c->add_option("--spp", a->spp, "Samples per pixel, or passes for sppm (default: the scene's)")->check(CLI::PositiveNumber);
  c->add_option("--integrator", a->integrator, "path | direct | photon | sppm (overrides the scene)");
  c->add_option("--strategy", a->strategy, "Environment strategy: uniform|cosine|bsdf|importance|alias|adaptive|mis");
  c->add_option("-D", a->defines, "Set a scene parameter: -D name=value (repeatable)");
  c->add_option("--threads", a->threads, "Worker threads (default: all cores)")->check(CLI::NonNegativeNumber);
  c->add_option("--seed", a->seed, "Sampler seed (overrides the scene)")->check(CLI::NonNegativeNumber);
  c->add_flag("--png", a->png, "Also write a tonemapped PNG beside the output");
  c->add_option("--exposure", a->exposure, "Exposure in stops for 8-bit output");
  c->add_flag("--aces", a->aces, "ACES-style tone curve for 8-bit output");
  c->add_flag("--no-progress", a->noProgress, "No progress bar");
  c->add_option("--checkpoint", a->checkpoint, "Seconds between writes of the image so far (0: never)");
  c->callback([a] { runRender(*a); });
}

}  // namespace envgi::cli
