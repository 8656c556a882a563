// `envgi study SCENE.xml -o DIR`: the paper's comparison as one command. A reference, then every
// strategy at each sample count (and time budget) with several seeds; RMSE and relMSE against the
// reference into results.csv / results.json and a self-contained report.html. Resumable: each
// finished run is a JSON file under DIR/runs, written atomically and skipped when re-run.
#include <fmt/format.h>
#include <spdlog/spdlog.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <functional>
#include <memory>
#include <set>
#include <nlohmann/json.hpp>
#include <sstream>
#include <stdexcept>

#include "accel/EmbreeAccel.h"
#include "cli/Commands.h"
#include "core/Files.h"
#include "envmap/CollapsedMap.h"
#include "gpu/CudaExecutor.h"
#include "render/Renderer.h"
#include "scene/SceneLoader.h"
#include "scene/NameTables.h"
#include "study/ErrorMetrics.h"
#include "study/Report.h"

namespace envgi::cli {

namespace {

namespace fs = std::filesystem;

struct StudyArgs {
  std::string scene, out, reference, strategies = "uniform,cosine,bsdf,adaptive,importance,mis,product,points-64",
                                     spp = "1,4,16,64,256", times, integrator = "direct";
  std::vector<std::string> defines;
  int seeds = 2, referenceSpp = 4096, threads = 0, gpu = 0;
  float noiseThreshold = 0.f;  // adaptive sampling in every run but the reference; 0: off
  int minSpp = 16;
  std::string device = "auto";
  std::string plan;  // where to write the runs still to do, instead of rendering them
  std::string ray;   // a Ray cluster's address: the runs go to envgi.distributed.study
};

std::vector<std::string> splitList(const std::string& s) {
  std::vector<std::string> out;
  std::stringstream ss(s);
  std::string item;
  while (std::getline(ss, item, ','))
    if (!item.empty()) out.push_back(item);
  return out;
}

// A list that names an item twice would run it twice and write its rows twice into results.csv
// (and the runs' files once, over each other): one error instead.
template <class T>
void requireNoRepeats(const std::vector<T>& items, const std::string& option) {
  for (size_t i = 0; i < items.size(); ++i)
    for (size_t j = 0; j < i; ++j)
      if (items[i] == items[j]) throw std::runtime_error(fmt::format("{} names '{}' twice", option, items[i]));
}

// A comma-separated list of positive finite numbers; `what` names the option in errors.
std::vector<double> positiveNumbers(const std::string& list, const std::string& option, const std::string& what) {
  std::vector<double> out;
  for (const std::string& s : splitList(list)) {
    double v = 0;
    if (!parseFiniteNumber(s, v) || !(v > 0)) throw std::runtime_error(option + ": '" + s + "' is not " + what);
    out.push_back(v);
  }
  return out;
}

// A run's largest sample count: a render's pass arithmetic is in int.
constexpr long long kMaxStudySpp = 2147483647;

// A strategy name of the study: a render strategy, points-N (the collapsed map with N lights,
// every one at each point) or points-draw-N (one of them drawn a light sample), each with its
// own sample counts (setStrategy) whatever the scene file asked for. A collapsed map's rows must
// say their size.
void applyStrategy(const std::string& name, Scene& scene) {
  const StrategyName* known = nullptr;
  for (const StrategyName& n : kStrategyNames)
    if (name == n.name) known = &n;
  if (known && isCollapsedMap(known->env)) throw std::runtime_error("strategy '" + name + "': name its size, " + name + "-N");
  if (!known && name.rfind("points-", 0) != 0) {
    std::string list;
    for (const StrategyName& n : kStrategyNames)
      list += (list.empty() ? "" : ", ") + std::string(n.name) + (isCollapsedMap(n.env) ? "-N" : "");
    throw std::runtime_error("unknown strategy '" + name + "' (" + list + ")");
  }
  scene.integrator.setStrategy(name);
}

// The sampler's seeds: the reference's, and each run's from its seed index.
constexpr uint32_t kReferenceSeed = 1000003u;
uint32_t runSeed(int seed) { return uint32_t(17 + 7919 * seed); }

struct Rendered {
  Image image;
  double seconds = 0.0;
  double meanSpp = 0.0;  // samples taken a pixel, on average
  std::string device;
};

// What renders the study's runs on the GPU: gpu::cudaPreparer, which builds the BVH on the first
// run and keeps it (only strategy and seed change between runs); unset, the CPU's prepareRender.
using Preparer = std::function<PreparedRender(const Scene&, const EmbreeAccel&, const RenderOptions&)>;

// One run on the study's scene, re-finalised per run for its strategy and seed (finalize keeps
// the vertex buffers Embree reads in place). Its seconds are the render's alone, without the
// GPU's scene upload, so that equal-time budgets compare sampling, not start-up.
Rendered renderOnce(const StudyArgs& a, Scene& scene, const EmbreeAccel& accel, const Preparer& prepare,
                    const std::string& strategy, int spp, uint32_t seed, bool reference = false) {
  applyStrategy(strategy, scene);
  scene.sampler.seed = seed;
  scene.finalize();
  RenderOptions o;
  o.spp = spp;
  o.progress = false;
  o.threads = a.threads;
  if (!reference) {
    o.noiseThreshold = a.noiseThreshold;
    o.adaptiveMinSpp = a.minSpp;
  }
  RenderStats st;
  Rendered r;
  PreparedRender pr = prepare ? prepare(scene, accel, o) : prepareRender(scene, accel, o);
  r.image = renderPasses(*pr.executor, scene.camera.width, scene.camera.height, pr.spp, o, &st);
  r.device = pr.executor->deviceName();
  r.seconds = st.seconds;
  r.meanSpp = double(st.pixelSamples) / (double(scene.camera.width) * double(scene.camera.height));
  return r;
}

std::string runKey(const StudyRun& r) {
  return r.timeBudget > 0 ? fmt::format("{}_time{}_seed{}", r.strategy, r.timeBudget, r.seed)
                          : fmt::format("{}_spp{}_seed{}", r.strategy, r.spp, r.seed);
}

nlohmann::json toJson(const StudyRun& r) {
  return {{"strategy", r.strategy}, {"spp", r.spp},          {"time_budget", r.timeBudget}, {"seed", r.seed},
          {"seconds", r.seconds},   {"rmse", r.rmse},        {"relmse", r.relMse},
          {"worst_region_rmse", r.worstRegionRmse}, {"device", r.device}, {"mean_spp", r.samplesTaken()}};
}

StudyRun fromJson(const nlohmann::json& j) {
  StudyRun r;
  r.strategy = j.at("strategy");
  r.spp = j.at("spp");
  r.timeBudget = j.at("time_budget");
  r.seed = j.at("seed");
  r.seconds = j.at("seconds");
  r.rmse = j.at("rmse");
  r.relMse = j.at("relmse");
  r.worstRegionRmse = j.value("worst_region_rmse", 0.0);
  r.device = j.value("device", std::string());
  r.meanSpp = j.value("mean_spp", 0.0);
  return r;
}

// How the reference is made: rendered here, or the file given.
std::string referenceDescription(const StudyArgs& a) {
  return a.reference.empty() ? fmt::format("rendered with mis at {} spp", a.referenceSpp)
                             : fs::absolute(a.reference).lexically_normal().string();
}

// What the runs in the output folder are made with: the scene file (name and a hash of its
// text), the -D values, the integrator and the reference. A re-run reuses the folder's runs only
// when these are the same, so old runs never mix with a changed scene or a new reference.
nlohmann::json studySettings(const StudyArgs& a) {
  std::ifstream f(a.scene, std::ios::binary);
  std::string xml((std::istreambuf_iterator<char>(f)), std::istreambuf_iterator<char>());
  uint64_t h = 1469598103934665603ull;  // FNV-1a, stable across builds
  for (unsigned char c : xml) h = (h ^ c) * 1099511628211ull;
  nlohmann::json defines = nlohmann::json::object();
  for (const auto& [k, v] : parseDefines(a.defines)) defines[k] = v;
  nlohmann::json s = {{"scene", fs::path(a.scene).filename().string()},
                      {"scene_fnv1a", fmt::format("{:016x}", h)},
                      {"defines", defines},
                      {"integrator", a.integrator},
                      {"reference", referenceDescription(a)}};
  // Recorded only when on, so that a folder made before adaptive sampling reads as it was.
  if (a.noiseThreshold > 0.f) s["adaptive_sampling"] = {{"noise_threshold", a.noiseThreshold}, {"min_spp", a.minSpp}};
  return s;
}

// Refuses a folder whose recorded settings differ from this run's, naming what differs; returns
// the settings to record once the reference has passed its checks.
nlohmann::json checkStudyFolder(const StudyArgs& a) {
  std::string path = a.out + "/study.json";
  nlohmann::json now = studySettings(a);
  if (fs::exists(path)) {
    nlohmann::json before;
    try {
      std::ifstream f(path);
      before = nlohmann::json::parse(f);
    } catch (const nlohmann::json::exception& e) {
      throw std::runtime_error(path + " is unreadable (" + e.what() + "); remove it or choose another -o folder");
    }
    if (before != now) {
      std::string diff;
      for (const auto& [key, value] : now.items())
        if (!before.contains(key) || before[key] != value)
          diff += fmt::format("{}{}: {} before, {} now", diff.empty() ? "" : "; ", key,
                              before.contains(key) ? before[key].dump() : "none", value.dump());
      for (const auto& [key, value] : before.items())
        if (!now.contains(key))
          diff += fmt::format("{}{}: {} before, none now", diff.empty() ? "" : "; ", key, value.dump());
      throw std::runtime_error(fmt::format("{} holds a study made with other settings ({}); choose another -o folder "
                                           "or remove it",
                                           a.out, diff));
    }
  } else if (!fs::is_empty(a.out + "/runs")) {
    spdlog::warn("study: {} has runs but no study.json (written before envgi recorded a study's settings): reusing them as they are",
                 a.out);
  }
  return now;
}

// A reference the runs can be measured against: finite, and the size the scene renders.
void checkReference(const Image& ref, const std::string& path, const Scene& scene) {
  if (nonFiniteValues(ref) > 0) throw std::runtime_error("reference '" + path + "' has NaN or infinite pixels");
  if (scene.camera.width != ref.width || scene.camera.height != ref.height)
    throw std::runtime_error(fmt::format("reference '{}' is {}x{}, the scene renders {}x{}", path, ref.width,
                                         ref.height, scene.camera.width, scene.camera.height));
}

void runStudy(const StudyArgs& a) {
  auto t0 = std::chrono::steady_clock::now();
  std::vector<std::string> strategies = splitList(a.strategies);
  std::vector<double> sppValues = positiveNumbers(a.spp, "--spp", "a positive sample count");
  std::vector<int> sppList;
  for (double v : sppValues) {
    if (v != std::floor(v)) throw std::runtime_error("--spp: '" + fmt::format("{}", v) + "' is not a positive sample count");
    if (v > double(kMaxStudySpp))  // it wrapped round to a negative count, and the runs went ahead
      throw std::runtime_error(fmt::format("--spp: {:.0f} is more than {} samples a pixel", v, kMaxStudySpp));
    sppList.push_back(int(v));
  }
  std::vector<double> times = positiveNumbers(a.times, "--time", "a positive number of seconds");
  if (strategies.empty()) throw std::runtime_error("--strategies is empty");
  if (sppList.empty()) throw std::runtime_error("--spp is empty");
  requireNoRepeats(strategies, "--strategies");
  requireNoRepeats(sppList, "--spp");
  requireNoRepeats(times, "--time");
  // In increasing order, whatever order they were given in: the plots and the report's middle
  // sample count (the one whose images it shows) read them so.
  std::sort(sppList.begin(), sppList.end());
  std::sort(times.begin(), times.end());
  if (!a.reference.empty()) requireRadianceImage(a.reference, "study");
  if (a.noiseThreshold > 0.f) {
    spdlog::info("study: adaptive sampling in every run, noise threshold {:g} from {} spp", a.noiseThreshold, a.minSpp);
    if (a.minSpp >= sppList.back())
      spdlog::warn("--min-spp {} is not below the largest --spp ({}): adaptive sampling never checks a pixel", a.minSpp,
                   sppList.back());
  }
  IntegratorType integrator = findIntegrator(a.integrator);
  if (!hasSampleKernel(integrator)) throw std::runtime_error("--integrator must be direct or path");
  Scene scene;
  loadScene(a.scene, parseDefines(a.defines), scene);
  scene.integrator.type = integrator;
  for (const std::string& s : strategies) {
    applyStrategy(s, scene);  // names checked before any work
    // path always joins one light sample to one BSDF sample by MIS: only the map's density is
    // the strategy's to choose, and a row must not be another's under a second name.
    const StrategyName& sn = findStrategy(scene.integrator.env.strategy);
    if (integrator == IntegratorType::Path && (sn.name == std::string("bsdf") || sn.name == std::string("mis") ||
                                               sn.env == EnvStrategy::PointsAll))
      throw std::runtime_error(fmt::format(
          "strategy '{}' names direct's samples; under --integrator path every vertex takes one light and one BSDF "
          "sample (MIS), so choose the map's density: uniform, cosine, importance, alias, adaptive, product or "
          "points-draw-N",
          s));
  }
  // Every strategy draws the same light where there is no map: the runs would differ in name only.
  if (!scene.env)
    throw std::runtime_error("study: '" + a.scene + "' has no environment map, so every strategy renders the same "
                             "image; the study compares ways of sampling one (add an <emitter type=\"envmap\">)");
  scene.finalize();
  const bool cuda = gpu::chooseCuda(a.device, "--device", &scene);
  EmbreeAccel accel(scene);
  Preparer prepare;
  if (cuda) {
    prepare = gpu::cudaPreparer(a.gpu);
    spdlog::info("study: rendering on cuda:{} ({})", a.gpu, gpu::deviceName(a.gpu));
  }
  // A given reference is read and checked before the folder is made, so that a wrong one leaves
  // nothing behind.
  Image ref;
  if (!a.reference.empty()) {
    ref = loadImage(a.reference);
    checkReference(ref, a.reference, scene);
    spdlog::info("study: reference {}", a.reference);
  }
  std::error_code made;
  fs::create_directories(a.out + "/runs", made);
  if (made)
    throw std::runtime_error(fmt::format("cannot make the study's folder '{}/runs': {}", a.out,
                                         fs::exists(a.out) && !fs::is_directory(a.out) ? "'" + a.out + "' is a file" : made.message()));
  std::string probe = a.out + "/.write_test";
  writeFileAtomically(probe, "ok");  // an unwritable folder fails here, before any rendering
  fs::remove(probe);
  nlohmann::json settings = checkStudyFolder(a);

  // The reference: given, or rendered once (and reused by a re-run).
  std::string refPath = a.reference.empty() ? a.out + "/reference.exr" : a.reference;
  if (a.reference.empty() && fs::exists(refPath)) {
    ref = loadImage(refPath);
    checkReference(ref, refPath, scene);
    spdlog::info("study: reference {}", refPath);
  } else if (a.reference.empty() && !a.plan.empty()) {
    // Settings checked and folder made: what is left is the reference, then the runs against it.
    nlohmann::json todo = {{"reference", {{"path", refPath}, {"strategy", "mis"}, {"spp", a.referenceSpp},
                                          {"seed", kReferenceSeed}, {"integrator", a.integrator}}},
                           {"runs", nlohmann::json::array()}};
    writeFileAtomically(a.plan, todo.dump(2));
    return;
  } else if (a.reference.empty()) {
    spdlog::info("study: rendering the reference, mis at {} spp", a.referenceSpp);
    Rendered r = renderOnce(a, scene, accel, prepare, "mis", a.referenceSpp, kReferenceSeed, true);
    ref = r.image;
    saveImage(ref, refPath);
    spdlog::info("study: reference done in {:.1f} s", r.seconds);
    checkReference(ref, refPath, scene);
  }
  writeFileAtomically(a.out + "/study.json", settings.dump(2));

  std::vector<StudyRun> plan;
  for (const std::string& s : strategies)
    for (int n : sppList)
      for (int seed = 0; seed < a.seeds; ++seed) plan.push_back({s, n, 0.0, seed});
  for (const std::string& s : strategies)
    for (double t : times)
      for (int seed = 0; seed < a.seeds; ++seed) plan.push_back({s, 0, t, seed});
  std::vector<StudyRun> runs;
  std::vector<StudyImage> images;
  int middleSpp = sppList[sppList.size() / 2];
  std::map<std::string, double> secondsPerSpp;  // from the equal-samples runs, for the time budgets
  int done = 0, skipped = 0;
  nlohmann::json todo = nlohmann::json::array();
  std::set<std::string> sppRunsToDo;  // strategies whose equal-samples runs are not all done
  for (StudyRun r : plan) {
    ++done;
    std::string key = runKey(r), json = a.out + "/runs/" + key + ".json", exr = a.out + "/runs/" + key + ".exr";
    bool wantImage = r.timeBudget == 0 && r.spp == middleSpp && r.seed == 0;
    bool reuse = fs::exists(json) && (!wantImage || fs::exists(exr));
    if (reuse) {
      // A run file that cannot be read (cut short by a full disk, edited) is rendered again.
      StudyRun planned = r;
      try {
        std::ifstream f(json);
        r = fromJson(nlohmann::json::parse(f));
        if (wantImage) images.push_back({r.strategy, r.spp, loadImage(exr)});
        ++skipped;
      } catch (const std::exception& e) {
        spdlog::warn("study: {} is unreadable ({}): rendering it again", json, e.what());
        r = planned;
        reuse = false;
      }
    }
    if (!reuse) {
      if (r.timeBudget > 0) {
        double sps = secondsPerSpp.count(r.strategy) ? secondsPerSpp[r.strategy] : 0.0;
        // Clamped before the cast: a budget of 1e12 s made a count past int's range (undefined).
        r.spp = sps > 0 ? int(std::clamp(r.timeBudget / sps, 1.0, double(kMaxStudySpp))) : 1;
      }
      if (!a.plan.empty()) {
        // A budget's sample count comes from the equal-samples runs' seconds: null until they are done.
        const bool waits = r.timeBudget > 0 && sppRunsToDo.count(r.strategy);
        if (r.timeBudget == 0) sppRunsToDo.insert(r.strategy);
        todo.push_back({{"key", key},
                        {"strategy", r.strategy},
                        {"spp", waits ? nlohmann::json() : nlohmann::json(r.spp)},
                        {"time_budget", r.timeBudget},
                        {"seed", r.seed},
                        {"render_seed", runSeed(r.seed)},
                        {"image", wantImage},
                        {"json", json},
                        {"exr", exr}});
        continue;
      }
      spdlog::info("study: [{}/{}] {} {} seed {}", done, plan.size(), r.strategy,
                   r.timeBudget > 0 ? fmt::format("{} s ({} spp)", r.timeBudget, r.spp) : fmt::format("{} spp", r.spp),
                   r.seed);
      Rendered img = renderOnce(a, scene, accel, prepare, r.strategy, r.spp, runSeed(r.seed));
      ImageError e = imageError(img.image, ref);
      r.seconds = img.seconds;
      r.device = img.device;
      r.meanSpp = img.meanSpp;
      r.rmse = e.rmse;
      r.relMse = e.relMse;
      r.worstRegionRmse = e.worstRegionRmse;
      if (wantImage) {
        saveImage(img.image, exr);
        images.push_back({r.strategy, r.spp, img.image});
      }
      writeFileAtomically(json, toJson(r).dump(2));
    }
    if (r.timeBudget == 0 && r.spp > 0) {
      double sps = r.seconds / r.spp;
      if (r.spp == sppList.back() || !secondsPerSpp.count(r.strategy)) secondsPerSpp[r.strategy] = sps;
    }
    runs.push_back(r);
  }
  if (!a.plan.empty()) {
    nlohmann::json adaptive = a.noiseThreshold > 0.f ? nlohmann::json{{"noise_threshold", a.noiseThreshold}, {"min_spp", a.minSpp}}
                                                     : nlohmann::json();
    writeFileAtomically(a.plan, nlohmann::json{{"reference", nullptr},
                                               {"reference_path", refPath},
                                               {"integrator", a.integrator},
                                               {"adaptive_sampling", adaptive},
                                               {"done", skipped},
                                               {"total", plan.size()},
                                               {"runs", todo}}
                                    .dump(2));
    return;
  }
  std::string csv = "strategy,spp,time_budget,seed,seconds,rmse,relmse,worst_region_rmse,device,mean_spp\n";
  nlohmann::json all = nlohmann::json::array();
  for (const StudyRun& r : runs) {
    csv += fmt::format("{},{},{},{},{:.6f},{:.8g},{:.8g},{:.8g},\"{}\",{:.6g}\n", r.strategy, r.spp, r.timeBudget,
                       r.seed, r.seconds, r.rmse, r.relMse, r.worstRegionRmse, r.device, r.samplesTaken());
    all.push_back(toJson(r));
  }
  writeFileAtomically(a.out + "/results.csv", csv);
  writeFileAtomically(a.out + "/results.json", nlohmann::json{{"scene", a.scene}, {"runs", all}}.dump(2));
  std::string defines;
  for (const auto& [k, v] : parseDefines(a.defines)) defines += (defines.empty() ? "" : ", ") + k + "=" + v;
  std::vector<std::pair<std::string, std::string>> howMade = {
      {"reference", referenceDescription(a)},
      {"integrator", a.integrator},
      {"image", fmt::format("{} x {}", ref.width, ref.height)},
      {"-D values", defines.empty() ? "none" : defines},
      {"seeds", std::to_string(a.seeds) + " (the tables give the median)"}};
  if (a.noiseThreshold > 0.f)
    howMade.push_back({"adaptive sampling", fmt::format("noise threshold {:g} from {} spp", a.noiseThreshold, a.minSpp)});
  writeFileAtomically(a.out + "/report.html", studyReportHtml(a.scene, runs, ref, images, strategies, howMade));
  spdlog::info("study: {} runs ({} already done) in {:.1f} s; wrote {}/report.html, results.csv, results.json",
               runs.size(), skipped,
               std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count(),
               fs::absolute(a.out).string());
}

// study --ray: the same study as Ray tasks, run by envgi.distributed in the Python this build
// made its module for (or $ENVGI_PYTHON), which calls this envgi back to plan and gather.
[[noreturn]] void runStudyOnRay(const StudyArgs& a) {
  if (!a.plan.empty()) throw std::runtime_error("--plan and --ray are each a way to run the study: choose one");
#ifdef ENVGI_PYTHON_EXECUTABLE
  const char* given = std::getenv("ENVGI_PYTHON");
  const std::string python = given && *given ? given : ENVGI_PYTHON_EXECUTABLE;
  nlohmann::json params = nlohmann::json::object();
  for (const auto& [k, v] : parseDefines(a.defines)) params[k] = v;
  auto listOf = [](const std::string& s) { return nlohmann::json(splitList(s)); };
  nlohmann::json spec = {{"scene", a.scene},
                         {"output", a.out},
                         {"address", a.ray == "local" ? nlohmann::json() : nlohmann::json(a.ray)},
                         {"strategies", listOf(a.strategies)},
                         {"spp", listOf(a.spp)},
                         {"time", a.times.empty() ? nlohmann::json() : listOf(a.times)},
                         {"seeds", a.seeds},
                         {"reference", a.reference.empty() ? nlohmann::json() : nlohmann::json(a.reference)},
                         {"reference_spp", a.referenceSpp},
                         {"integrator", a.integrator},
                         {"device", a.device},
                         {"noise_threshold", a.noiseThreshold},
                         {"min_spp", a.minSpp},
                         {"threads", a.threads > 0 ? a.threads : 1},  // a task renders with the CPUs it asks Ray for
                         {"progress", spdlog::should_log(spdlog::level::info)},
                         {"params", params}};
  std::string pythonPath = ENVGI_PYTHON_PATH;
  if (const char* p = std::getenv("PYTHONPATH"); p && *p) pythonPath += std::string(":") + p;
  setenv("PYTHONPATH", pythonPath.c_str(), 1);
  setenv("ENVGI_CLI", fs::read_symlink("/proc/self/exe").c_str(), 1);
  const std::string json = spec.dump();
  std::vector<const char*> argv = {python.c_str(), "-m", "envgi.distributed", "--study", json.c_str(), nullptr};
  std::fflush(nullptr);
  execv(python.c_str(), const_cast<char* const*>(argv.data()));
  throw std::runtime_error(fmt::format("--ray: cannot run {} ({})", python, std::strerror(errno)));
#else
  throw std::runtime_error("--ray: this envgi was built without its Python package (ENVGI_PYTHON), which runs the "
                           "study on Ray");
#endif
}

}  // namespace

void addStudyCommand(CLI::App& app) {
  auto a = std::make_shared<StudyArgs>();
  CLI::App* c = app.add_subcommand("study", "Compare environment strategies against a reference (RMSE, plots, report)");
  c->add_option("scene", a->scene, "Scene file (.xml)")->required()->check(CLI::ExistingFile);
  c->add_option("-o,--output", a->out, "Output folder (results.csv, results.json, report.html, runs/)")->required();
  c->add_option("--strategies", a->strategies, "Comma-separated: uniform,cosine,bsdf,importance,alias,adaptive,mis,product,points-N (every one of N "
                "collapsed-map lights at each point), points-draw-N (one of them a sample)");
  c->add_option("--spp", a->spp, "Comma-separated sample counts (default 1,4,16,64,256)");
  c->add_option("--time", a->times, "Comma-separated time budgets in seconds for equal-time runs");
  // Each seed is one more run of every configuration; 10^8 of them had ended in std::bad_alloc.
  c->add_option("--seeds", a->seeds, "Seeds per configuration (default 2), at most 1000")->check(wholeNumberFrom(1, 1000));
  c->add_option("--reference", a->reference, "Reference image (.exr, .pfm, .hdr); default: rendered with mis");
  c->add_option("--reference-spp", a->referenceSpp, "Samples for the rendered reference (default 4096)")->check(atLeast(1));
  c->add_option("--integrator", a->integrator, "direct (default) or path");
  c->add_option("-D", a->defines, "Set a scene parameter: -D name=value (repeatable)");
  addThreadsOption(c, &a->threads);
  c->add_option("--device", a->device, "cpu | cuda | auto (default: auto, CUDA where a GPU is present)");
  c->add_option("--gpu", a->gpu, "Which CUDA device (default 0)")->check(atLeast(0));
  c->add_option("--noise-threshold", a->noiseThreshold,
                "Adaptive sampling in every run (not the reference): a pixel stops once its noise is below this "
                "(as render's; default 0: off)")
      ->check(atLeast(0))
      ->check(finiteNumber());
  c->add_option("--min-spp", a->minSpp, "With --noise-threshold: samples every pixel takes first (default 16)")
      ->check(atLeast(2));
  // For envgi.distributed.study, which renders the runs as Ray tasks, writes their files, then
  // runs the study once more to gather them into the same results and report.
  c->add_option("--plan", a->plan,
                "Check the settings, make the folder, and write the runs still to do (and the reference, where it "
                "is missing) to this JSON file instead of rendering them");
  c->add_option("--ray", a->ray,
                "Run the study on a Ray cluster: its address (HOST:PORT, auto) or 'local' to start Ray here; the "
                "same results and report (needs the Python package and Ray: scripts/install-deps.sh)");
  c->callback([a] {
    if (!a->ray.empty()) runStudyOnRay(*a);
    runStudy(*a);
  });
}

}  // namespace envgi::cli
