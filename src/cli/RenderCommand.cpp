// `envgi render SCENE.xml -o OUT.exr`: the renderer from the command line, on the CPU or a GPU.
#include <fmt/format.h>
#include <fmt/ranges.h>
#include <spdlog/spdlog.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <csignal>
#include <filesystem>
#include <functional>
#include <memory>
#include <sstream>
#include <stdexcept>
#include <tuple>

#include <unistd.h>

#include "accel/Bvh.h"
#include "accel/EmbreeAccel.h"
#include "cli/Commands.h"
#include "core/Files.h"
#include "core/PhysicalMemory.h"
#include "envmap/CollapsedMap.h"
#include "gpu/CudaExecutor.h"
#include "render/AovRenderer.h"
#include "render/Renderer.h"
#include "render/SplitRender.h"
#include "scene/SceneLoader.h"
#include "scene/NameTables.h"

namespace envgi::cli {

namespace {

std::atomic<bool> g_cancel{false};
std::atomic<int> g_signal{0};  // the first stopping signal, for the exit status
// The first SIGINT or SIGTERM asks the render to stop after the tiles in flight (the first pass,
// and a GPU's, after the pass) and write what is finished; a second one ends the process at
// once, as the signal's default would.
extern "C" void onInterrupt(int sig) {
  if (g_cancel.exchange(true)) {
    std::signal(sig, SIG_DFL);
    std::raise(sig);
    return;
  }
  g_signal = sig;
  static const char msg[] = "\nenvgi: stopping after the tiles in flight, keeping every finished sample (again to stop now)\n";
  ssize_t ignored = write(2, msg, sizeof(msg) - 1);  // async-signal-safe, unlike the logger
  (void)ignored;
}

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
  double timeLimit = 0.0;
  float noiseThreshold = 0.f;
  int minSpp = 16;
  std::string sampleMap;
  std::string aov;
  bool aovGiven = false;
  std::string device = "auto", sampler, pointMethod, filter;
  int points = 0;
  int gpu = 0;
  std::string gpus;     // all | 0,1,2: the node's GPUs the render splits over
  std::string samples;  // S0:S1, a share of the render
};

// --gpus all | 0,1,2: the devices a render splits over, of the `present` this machine has;
// the list's form is checked before the count is asked for.
std::vector<int> gpusOf(const std::string& text, const std::function<int()>& present) {
  std::vector<int> list;
  if (text != "all") {
    std::stringstream ss(text);
    std::string item;
    while (std::getline(ss, item, ',')) {
      size_t used = 0;
      int g = -1;
      try {
        g = std::stoi(item, &used);
      } catch (const std::exception&) {
      }
      if (g < 0 || used != item.size() || item.empty())
        throw std::runtime_error("--gpus " + text + ": give all, or device numbers separated by commas (0,1,2)");
      if (std::find(list.begin(), list.end(), g) != list.end())
        throw std::runtime_error(fmt::format("--gpus {}: names GPU {} twice", text, g));
      list.push_back(g);
    }
    if (list.empty()) throw std::runtime_error("--gpus: give all, or device numbers separated by commas (0,1,2)");
  }
  const int n = present();
  if (text == "all")
    for (int g = 0; g < n; ++g) list.push_back(g);
  for (int g : list)
    if (g >= n) throw std::runtime_error(fmt::format("--gpus {}: there is no GPU {} ({} present)", text, g, n));
  return list;
}

// --samples S0:S1: samples [S0, S1) of the render's sequence (0 <= S0 < S1; renderPasses checks
// them against the spp).
std::pair<int, int> sampleRangeOf(const std::string& text) {
  const size_t colon = text.find(':');
  int s0 = -1, s1 = -1;
  size_t used0 = 0, used1 = 0;
  try {
    s0 = std::stoi(text.substr(0, colon), &used0);
    s1 = std::stoi(text.substr(colon + 1), &used1);
  } catch (const std::exception&) {
    s0 = -1;
  }
  if (colon == std::string::npos || used0 != colon || used1 != text.size() - colon - 1 || s0 < 0 || s1 <= s0)
    throw std::runtime_error("--samples " + text + ": give S0:S1, whole numbers with 0 <= S0 < S1");
  return {s0, s1};
}

double secondsSince(std::chrono::steady_clock::time_point t) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t).count();
}

// "a", "a and b", "a, b and c".
std::string listInWords(const std::vector<std::string>& items) {
  if (items.size() < 2) return items.empty() ? "" : items[0];
  return fmt::format("{} and {}", fmt::join(items.begin(), items.end() - 1, ", "), items.back());
}


void runRender(const RenderArgs& a) {
  namespace fs = std::filesystem;
  // Both images are checked before the render, so a bad name or folder cannot cost its samples.
  auto requireImageName = [](const std::string& path, const std::string& what) {
    return requireOutputExtension(path, {".exr", ".pfm", ".hdr", ".png"}, what);
  };
  // Its folders are made as study makes its own: `-o out/x.exr` on a fresh checkout works.
  makeParentDirectories(a.output);
  if (!a.sampleMap.empty()) makeParentDirectories(a.sampleMap);
  std::string ext = requireImageName(a.output, "output");
  // What the render writes at each checkpoint and at the end: the image and, with --png, the
  // tone-mapped PNG beside it.
  std::vector<std::string> images = {a.output};
  if (a.png && ext != ".png") images.push_back(fs::path(a.output).replace_extension(".png").string());
  for (size_t i = 1; i < images.size(); ++i) requireWritableDirectoryOf(images[i]);
  if (!a.sampleMap.empty()) {
    requireImageName(a.sampleMap, "--sample-map");
    // Written after the image, it would replace it (or the PNG beside it) without a word.
    const fs::path map = fs::weakly_canonical(a.sampleMap);
    for (const std::string& image : images)
      if (map == fs::weakly_canonical(image))
        throw std::runtime_error("--sample-map '" + a.sampleMap + "' would overwrite the rendered image: give it a name of its own");
  }
  auto t0 = std::chrono::steady_clock::now();
  Scene scene;
  loadScene(a.scene, parseDefines(a.defines), scene);
  if (!a.integrator.empty()) {
    scene.integrator.type = findIntegrator(a.integrator);
  }
  if (!a.strategy.empty()) {
    scene.integrator.setStrategy(a.strategy);
  }
  if (a.points > 0) scene.integrator.env.pointCount = a.points;
  if (!a.pointMethod.empty()) scene.integrator.env.pointMethod = a.pointMethod;  // Scene::finalize checks it
  if (a.seed >= 0) scene.sampler.seed = uint32_t(a.seed);
  if (!a.sampler.empty()) scene.sampler.type = findSampler(a.sampler);
  // A type other than the scene's takes Mitsuba's default parameters; the scene's own keeps its.
  if (!a.filter.empty()) {
    FilterType t = findName(kFilterNames, a.filter, "filter");
    if (t != scene.camera.filter.type) scene.camera.filter = makeFilter(t);
  }
  if (a.aovGiven) scene.aovs = parseAovs(a.aov);
  if (!scene.aovs.empty() && ext != ".exr")
    throw std::runtime_error("AOVs are written as channels of an OpenEXR file: the output '" + a.output +
                             "' must end in .exr");
  // The film's alpha (pixel_format rgba) is the A channel, first after R, G, B as in Mitsuba's
  // files; an .exr and a .png hold it (the PNG beside an .exr too), .hdr and .pfm do not.
  if (scene.filmAlpha && (ext == ".exr" || ext == ".png" || a.png))
    scene.aovs.insert(scene.aovs.begin(), Aov{"", AovType::Alpha});
  if (scene.filmAlpha && ext != ".exr" && ext != ".png")
    spdlog::warn("the film's pixel_format has alpha, which {} cannot hold: it gets RGB", a.output);
  scene.finalize();
  // Options that change nothing here are said, not silently dropped.
  if (!a.strategy.empty() && !scene.env)
    spdlog::warn("--strategy {}: the scene has no environment map, so no strategy draws from one", a.strategy);
  if ((a.points > 0 || !a.pointMethod.empty()) && !isCollapsedMap(findStrategy(scene.integrator.env.strategy).env))
    spdlog::warn("--points and --point-method shape the collapsed map, which strategy '{}' does not use (points or "
                 "points-draw do)",
                 scene.integrator.env.strategy);
  requireLight(scene);  // as photons says it
  if (!a.gpus.empty() && a.device == "cpu") throw std::runtime_error("--gpus: the render is on the CPU (--device cpu)");
  std::vector<int> gpus;  // with more than one, the render splits over them
  int gpuIndex = a.gpu;
  if (!a.gpus.empty()) {
    gpus = gpusOf(a.gpus, [] {
      std::string why;
      const int n = gpu::deviceCount(&why);
      if (n == 0) throw std::runtime_error("--gpus: no CUDA device (" + why + ")");
      return n;
    });
    const IntegratorType t = scene.integrator.type;
    if (gpus.size() > 1 && t != IntegratorType::Path && t != IntegratorType::Direct)
      throw std::runtime_error(fmt::format("--gpus: only path and direct split over several GPUs; {} renders on one "
                                           "(--gpus N)",
                                           integratorName(t)));
    gpuIndex = gpus[0];
  }
  const bool cuda = gpu::chooseCuda(a.gpus.empty() ? a.device : "cuda", "--device", &scene);
  double loadSeconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  spdlog::info("scene {}: {} triangles, {} spheres, {} area-light primitives{}{}, {:.1f} MB of geometry, loaded in {:.2f} s",
               a.scene, scene.triangleCount(), scene.spheres.size(), scene.lightCount(),
               scene.deltaLights.empty() ? "" : fmt::format(", {} directional/point/spot lights", scene.deltaLights.size()),
               scene.env ? ", environment map" : "", scene.geometryBytes() / 1e6, loadSeconds);

  SaveOptions so;
  so.exposure = a.exposure;
  so.toneMap = a.aces ? ToneMap::Aces : ToneMap::Clamp;
  std::vector<ImageChannel> aovs;
  // The image, with its AOVs, to each of `paths`.
  auto write = [&](const Image& img, const std::vector<std::string>& paths) {
    const Image* out = &img;
    Image withAovs;  // a copy only where there are channels to add
    if (!aovs.empty()) {
      withAovs = img;
      withAovs.channels = aovs;
      out = &withAovs;
    }
    for (const std::string& path : paths) saveImage(*out, path, so);
  };
  // The AOVs take only camera rays, traced here on the CPU before the image (so that every
  // checkpoint holds them), whichever device renders it.
  auto traceAovs = [&](const EmbreeAccel& accel, int spp) {
    if (scene.aovs.empty()) return;
    auto t = std::chrono::steady_clock::now();
    aovs = renderAovs(scene, accel, spp, a.threads);
    std::string names;
    for (const ImageChannel& c : aovs) names += (names.empty() ? "" : ", ") + c.name;
    spdlog::info("AOVs {} from {} camera samples a pixel in {:.2f} s", names, std::min(spp, kAovMaxSamples),
                 secondsSince(t));
  };

  RenderOptions ro;
  ro.spp = a.spp;
  ro.threads = a.threads;
  ro.progress = !a.noProgress && spdlog::should_log(spdlog::level::info);  // -q: errors and warnings only, as pbrt's --quiet
  ro.checkpointSeconds = a.checkpoint;
  // A checkpoint that cannot be written (a full disk, the folder gone) is a warning: the render
  // goes on with its samples and tries again at the next checkpoint and at the end.
  ro.checkpoint = [&](const Image& img, int done) {
    try {
      write(img, images);
    } catch (const std::exception& e) {
      spdlog::warn("checkpoint at {} spp not written ({}); rendering on", done, e.what());
      return;
    }
    spdlog::info("checkpoint: {} spp written to {}", done, a.output);
  };
  ro.cancel = &g_cancel;
  ro.timeLimitSeconds = a.timeLimit;
  ro.noiseThreshold = a.noiseThreshold;
  if (!a.samples.empty()) {
    // A share of the render: the image is the mean of its samples, which shares of equal
    // weight average into the whole (envgi.distributed adds their sums instead).
    // (The preparation refuses other integrators, a time limit and adaptive sampling.)
    std::tie(ro.firstSample, ro.sampleEnd) = sampleRangeOf(a.samples);
  }
  ro.adaptiveMinSpp = a.minSpp;
  std::vector<int> samples;
  if (!a.sampleMap.empty()) ro.samplesOut = &samples;
  for (const Aov& aov : scene.aovs) ro.aovChannels += int(aovChannelNames(aov).size());
  // Before the AOVs, which are traced first and are as large as the film.
  requireFilmFits(scene.camera, ro, physicalMemoryBytes());
  std::signal(SIGINT, onInterrupt);
  std::signal(SIGTERM, onInterrupt);
  RenderStats st;
  const IntegratorSettings& is = scene.integrator;
  const int requestedSpp = a.spp > 0 ? a.spp : scene.sampler.sampleCount;
  spdlog::info("rendering {}x{} with '{}' (strategy {}), {} spp, {} sampler, {} filter{}", scene.camera.width,
               scene.camera.height, integratorName(is.type), is.env.strategy, requestedSpp,
               samplerName(scene.sampler.type), nameOf(kFilterNames, scene.camera.filter.type),
               a.noiseThreshold > 0.f
                   ? fmt::format(", adaptive: noise threshold {:g} from {} spp", a.noiseThreshold, a.minSpp)
                   : "");
  if (a.noiseThreshold > 0.f && a.minSpp >= requestedSpp)
    spdlog::warn("--min-spp {} is not below the {} spp asked for: adaptive sampling never checks a pixel", a.minSpp,
                 requestedSpp);
  Image img;
  if (cuda) {
    Bvh bvh(scene);
    const BvhBuildStats& bs = bvh.stats();
    spdlog::info("BVH: {} triangles, {} nodes, depth {}, {:.1f} bytes a triangle, built in {:.2f} s", bs.triangles,
                 bs.nodes, bs.maxDepth, bs.triangles ? double(bs.bytes()) / double(bs.triangles) : 0.0, bs.seconds);
    std::unique_ptr<EmbreeAccel> accel;
    if (scene.integrator.type == IntegratorType::Photon || !scene.aovs.empty())
      accel = std::make_unique<EmbreeAccel>(scene);
    if (accel) traceAovs(*accel, requestedSpp);
    if (scene.integrator.type != IntegratorType::Photon) accel.reset();
    auto t2 = std::chrono::steady_clock::now();
    if (gpus.size() > 1) {
      // Each GPU a share of the samples, its film added to the others' (render/SplitRender.h).
      spdlog::info("splitting {} spp over {} GPUs; no checkpoints while they render", requestedSpp, gpus.size());
      img = renderSplit(scene.camera.width, scene.camera.height, kernelSettings(scene, ro).spp, int(gpus.size()), ro,
                        [&](const RenderOptions& share, int i) {
                          size_t bytes = 0;
                          PreparedRender pr = gpu::prepareCudaRender(scene, bvh, nullptr, share, gpus[size_t(i)], &bytes);
                          spdlog::info("device: {}: ready in {:.2f} s, {:.1f} MB of device memory",
                                       pr.executor->deviceName(), secondsSince(t2), bytes / 1e6);
                          return pr;
                        },
                        &st);
    } else {
      size_t bytes = 0;
      PreparedRender pr = gpu::prepareCudaRender(scene, bvh, accel.get(), ro, gpuIndex, &bytes);
      spdlog::info("device: {}: ready in {:.2f} s, {:.1f} MB of device memory", pr.executor->deviceName(),
                   secondsSince(t2), bytes / 1e6);
      img = renderPasses(*pr.executor, scene.camera.width, scene.camera.height, pr.spp, ro, &st);
      logExecutorStats(*pr.executor);
    }
  } else {
    auto t1 = std::chrono::steady_clock::now();
    EmbreeAccel accel(scene);
    spdlog::info("device: CPU; Embree BVH built in {:.2f} s ({:.1f} MB)", secondsSince(t1), double(accel.bytes()) / 1e6);
    traceAovs(accel, requestedSpp);
    img = render(scene, accel, ro, &st);
  }
  std::signal(SIGINT, SIG_DFL);
  std::signal(SIGTERM, SIG_DFL);
  // Each file the render made, written where it was asked for; one that cannot be written now
  // (it could at the start: a full disk, the folder gone) goes to the temporary folder instead,
  // so that no sample is lost, and the command fails naming where each went.
  std::string firstError;
  std::vector<std::string> rescued, lost;  // quoted, for the error line
  auto keep = [&](const std::string& path, const std::function<void(const std::string&)>& save) {
    try {
      save(path);
    } catch (const std::exception& e) {
      if (firstError.empty()) firstError = e.what();
      try {  // no temporary folder (TMPDIR gone) is one more place it cannot go, not a new error
        const std::string name =
            fmt::format("envgi-rescue-{}-{}", static_cast<long>(::getpid()), fs::path(path).filename().string());
        const std::string rescue = (fs::temp_directory_path() / name).string();
        save(rescue);
        rescued.push_back("'" + rescue + "'");
      } catch (const std::exception&) {
        lost.push_back("'" + path + "'");
      }
    }
  };
  for (const std::string& image : images) keep(image, [&](const std::string& path) { write(img, {path}); });
  if (!a.sampleMap.empty()) {
    // Each pixel's share of the requested samples: 1 where it took them all.
    Image map(scene.camera.width, scene.camera.height);
    for (size_t i = 0; i < samples.size(); ++i)
      map.rgb[3 * i] = map.rgb[3 * i + 1] = map.rgb[3 * i + 2] = float(samples[i]) / float(requestedSpp);
    keep(a.sampleMap, [&](const std::string& path) { saveImage(map, path, SaveOptions{}); });
  }
  if (!firstError.empty()) {
    if (rescued.empty()) throw std::runtime_error(firstError);
    std::string message = fmt::format("{}; the {} spp rendered were written to {} instead", firstError, st.sppDone,
                                      listInWords(rescued));
    if (!lost.empty()) message += fmt::format("; {} could not be written anywhere", listInWords(lost));
    throw std::runtime_error(message);
  }
  if (st.converged)
    spdlog::info("adaptive sampling: every pixel met the noise threshold after {} of {} spp", st.sppDone,
                 requestedSpp);
  if (a.noiseThreshold > 0.f) {
    double full = double(scene.camera.width) * scene.camera.height * st.sppDone;
    spdlog::info("adaptive sampling: {:.3g} samples, {:.1f}% of {} spp everywhere; {:.1f}% of the pixels stopped early",
                 double(st.pixelSamples), full > 0 ? 100.0 * double(st.pixelSamples) / full : 0.0, st.sppDone,
                 100.0 * double(st.pixelsStopped) / (double(scene.camera.width) * scene.camera.height));
  }
  if (st.cancelled && st.pixelsAhead > 0)
    spdlog::warn("interrupted: wrote the {} samples per pixel finished so far, and {} in {} pixels ({:.1f}%) whose "
                 "tiles had finished the pass in flight",
                 st.sppDone, st.sppAhead, st.pixelsAhead,
                 100.0 * double(st.pixelsAhead) / (double(scene.camera.width) * scene.camera.height));
  else if (st.cancelled)
    spdlog::warn("interrupted: wrote the {} samples per pixel finished so far", st.sppDone);
  if (st.timeLimited)
    spdlog::info("time limit of {:g} s: stopped after {} of {} spp", a.timeLimit, st.sppDone, requestedSpp);
  spdlog::info("done in {:.2f} s: {} spp, {:.3g} rays, {:.3g} Mrays/s", st.seconds, st.sppDone, double(st.rays),
               st.raysPerSecond() / 1e6);
  std::vector<std::string> written;
  for (const std::string& image : images) written.push_back(fs::absolute(image).string());
  spdlog::info("wrote {}", fmt::join(written, " and "));
  // A script must tell a stopped render from a finished one: 130 (SIGINT) or 143 (SIGTERM).
  if (st.cancelled && g_signal > 0) throw ExitStatus{128 + g_signal.load()};
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
  c->add_option("--spp", a->spp, "Samples per pixel, or passes for sppm (default: the scene's)")->check(atLeast(1));
  c->add_option("--integrator", a->integrator, "Integrator: " + nameList(kIntegratorNames) + " (overrides the scene)");
  c->add_option("--strategy", a->strategy, "Environment strategy: " + strategyNameList());
  c->add_option("--points", a->points, "points: directional lights in the collapsed map (default 64)")
      ->check(wholeNumberFrom(1, kMaxCollapsedPoints));
  c->add_option("--point-method", a->pointMethod, "points: sample (Algorithm 1 draws, power L/pdf/N) | mediancut")
      ->check(CLI::IsMember({"sample", "mediancut"}));  // Scene::finalize checks it only where a map is collapsed
  c->add_option("-D", a->defines, "Set a scene parameter: -D name=value (repeatable)");
  addThreadsOption(c, &a->threads);
  // The sampler's seed is 32 bits: a larger one had been cut to its low bits without a word.
  c->add_option("--seed", a->seed, "Sampler seed (overrides the scene)")->check(wholeNumberFrom(0, 4294967295LL));
  c->add_flag("--png", a->png, "Also write a tonemapped PNG beside the output");
  c->add_option("--exposure", a->exposure, "Exposure in stops for 8-bit output")->check(finiteNumber());
  c->add_flag("--aces", a->aces, "ACES-style tone curve for 8-bit output");
  c->add_flag("--no-progress", a->noProgress, "No progress bar");
  c->add_option("--checkpoint", a->checkpoint, "Seconds between writes of the image so far (0: never)")->check(atLeast(0));
  c->add_option("--time-limit", a->timeLimit,
                "Seconds of sampling at most: stop at the last pass that fits, with the samples done (0: none)")
      ->check(atLeast(0));
  c->add_option("--samples", a->samples,
                "S0:S1: only samples [S0, S1) of the render's --spp, for splitting one render over machines (path, "
                "direct)");
  c->add_option("--noise-threshold", a->noiseThreshold,
                "Adaptive sampling: a pixel stops once its noise (standard error of its mean luminance over the "
                "root of that mean) and its neighbours' is below this, as Cycles' noise threshold (0: off)")
      ->check(atLeast(0))
      ->check(finiteNumber());
  c->add_option("--min-spp", a->minSpp, "Adaptive sampling: samples every pixel takes before it may stop (default 16)")
      ->check(atLeast(2));
  c->add_option("--sample-map", a->sampleMap,
                "Also write each pixel's share of the requested samples as an image (.exr, .pfm, .hdr or .png)");
  c->add_option("--aov", a->aov,
                "AOVs written as channels of the .exr beside the image, Mitsuba's name:type list (types albedo, "
                "depth, position, uv, geo_normal, sh_normal, prim_index, shape_index), e.g. albedo:albedo,nn:sh_normal; "
                "replaces the scene's aov integrator's list ('' for none)")
      ->each([a](const std::string&) { a->aovGiven = true; });
  c->add_option("--device", a->device, "cpu | cuda | auto (default: auto, CUDA where a GPU is present)");
  CLI::Option* one = c->add_option("--gpu", a->gpu, "Which CUDA device (default 0)")->check(atLeast(0));
  c->add_option("--gpus", a->gpus,
                "Split the render's samples over several CUDA devices of this machine: all, or a list (0,1,2); "
                "path and direct")
      ->excludes(one);
  c->add_option("--filter", a->filter, "Pixel filter: " + nameList(kFilterNames) + " (overrides the scene)");
  c->add_option("--sampler", a->sampler, "Sample sequence: " + nameList(kSamplerNames) + " (overrides the scene)");
  c->callback([a] { runRender(*a); });
}

}  // namespace envgi::cli
