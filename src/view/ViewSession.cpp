#include "view/ViewSession.h"

#include <spdlog/spdlog.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <map>
#include <nlohmann/json.hpp>

#include "core/PhysicalMemory.h"
#include "render/ActivePixels.h"
#include "scene/NameTables.h"

namespace envgi {

using json = nlohmann::json;
using Clock = std::chrono::steady_clock;

struct ViewSession::State {
  Vec3f origin, target, up;
  int cameraVersion = 0;
  float exposure = 0.f;
  ToneMap tone = ToneMap::Clamp;
  float envRotation = 0.f, envScale = 1.f;  // degrees about +Y on top of the file's placement
  std::string strategy, integrator;
  float resolutionScale = 1.f;
  float noiseThreshold = 0.f;  // adaptive sampling (AdaptiveSampling.h); 0: off
  int minSpp = 16;
  int sceneVersion = 0;  // bumped by what every executor depends on (environment, strategy)
  bool restart = true;   // the camera or resolution changed: an empty film
  bool rebuild = true;   // the integrator, strategy or environment changed: a new executor
  bool toneChanged = false;
  bool frameRequested = true;
  bool resend = false;  // a new page: send the film as it is, even if the last page had it
};

namespace {
// JSON numbers are doubles; one beyond a float's range would make the conversion undefined, so
// each is range-checked as a double first.
float finiteFloat(const json& v, const char* key) {
  double d = v.get<double>();
  if (!(std::fabs(d) <= 3.0e38)) throw std::runtime_error(std::string("'") + key + "' must be finite");
  return float(d);
}
Vec3f vec3(const json& j, const char* key) {
  const json& v = j.at(key);
  if (!v.is_array() || v.size() != 3) throw std::runtime_error(std::string("'") + key + "' must be 3 numbers");
  return Vec3f(finiteFloat(v[0], key), finiteFloat(v[1], key), finiteFloat(v[2], key));
}
json arr(Vec3f v) { return json::array({v.x, v.y, v.z}); }
float number(const json& j, const char* key, float lo, float hi) {
  double v = j.at(key).get<double>();
  if (!(v >= lo && v <= hi)) throw std::runtime_error(fmt::format("'{}' must be in [{}, {}]", key, lo, hi));
  return float(v);
}
}  // namespace

ViewSession::ViewSession(std::unique_ptr<Scene> scene, std::string scenePath, ViewOptions opts)
    : scene_(std::move(scene)), scenePath_(std::move(scenePath)), opts_(opts), state_(std::make_unique<State>()) {
  scene_->finalize();
  accel_ = std::make_unique<EmbreeAccel>(*scene_);
  const Transform& t = scene_->camera.toWorld;
  State& s = *state_;
  s.origin = t.point(Vec3f(0.f));
  Vec3f fwd = normalize(t.vector(Vec3f(0.f, 0.f, 1.f)));
  const SceneView& sc = scene_->view();
  Vec3f centre = (sc.boundsMin + sc.boundsMax) * 0.5f;
  float dist = std::max(dot(centre - s.origin, fwd), 1e-2f * length(sc.boundsMax - sc.boundsMin) + 1e-3f);
  s.target = s.origin + fwd * dist;
  s.up = normalize(t.vector(Vec3f(0.f, 1.f, 0.f)));
  if (scene_->camera.orthographic) cameraShape_ = lookAt(s.origin, s.target, s.up).inverse() * t;
  s.strategy = scene_->integrator.env.strategy;
  s.integrator = integratorName(scene_->integrator.type);
  s.noiseThreshold = opts_.noiseThreshold;
  s.minSpp = opts_.adaptiveMinSpp;
}

ViewSession::~ViewSession() { stop(); }

void ViewSession::start(std::function<void(ViewFrame)> sink) {
  sink_ = std::move(sink);
  worker_ = std::thread([this] { run(); });
}

void ViewSession::stop() {
  stop_ = true;
  wake_.notify_all();
  if (worker_.joinable()) worker_.join();
}

std::string ViewSession::hello() const {
  std::lock_guard<std::mutex> lock(mutex_);
  const State& s = *state_;
  const SceneView& sc = scene_->view();
  json integrators = json::array(), strategies = json::array();
  for (const auto& n : kIntegratorNames)
    if (!n.alias) integrators.push_back(n.name);
  for (const auto& n : kStrategyNames) strategies.push_back(n.name);
  json j = {{"type", "hello"},
            {"scene", std::filesystem::path(scenePath_).filename().string()},
            {"width", scene_->camera.width},
            {"height", scene_->camera.height},
            {"tanHalfY", scene_->camera.tanHalfY},
            {"camera", {{"origin", arr(s.origin)}, {"target", arr(s.target)}, {"up", arr(s.up)}}},
            {"bounds", {{"min", arr(sc.boundsMin)}, {"max", arr(sc.boundsMax)}}},
            {"integrators", integrators},
            {"strategies", strategies},
            {"integrator", s.integrator},
            {"strategy", s.strategy},
            {"noiseThreshold", s.noiseThreshold},
            {"minSpp", s.minSpp},
            {"hasEnvironment", scene_->env != nullptr}};
  return j.dump();
}

std::string ViewSession::handle(const std::string& message) {
  json j = json::parse(message, nullptr, false);
  if (j.is_discarded() || !j.is_object() || !j.contains("type") || !j["type"].is_string())
    throw std::runtime_error("malformed message (not a JSON object with a 'type')");
  std::string type = j["type"];
  static const char* known[] = {"next", "save", "camera", "exposure", "tonemap", "environment", "strategy",
                                "integrator", "resolution", "adaptive"};
  if (std::find(std::begin(known), std::end(known), type) == std::end(known))
    throw std::runtime_error("unknown message type '" + type + "'");
  try {
    if (type == "next") {
      requestFrame();
      return "";
    }
    if (type == "save") return json{{"type", "saved"}, {"path", saveExr()}}.dump();
    std::lock_guard<std::mutex> lock(mutex_);
    State next = *state_;
    if (type == "camera") {
      next.origin = vec3(j, "origin");
      next.target = vec3(j, "target");
      next.up = vec3(j, "up");
      if (length(next.target - next.origin) < 1e-6f || length(cross(next.target - next.origin, next.up)) < 1e-6f)
        throw std::runtime_error("camera: origin, target and up must span a frame");
      next.cameraVersion = next.cameraVersion + 1;
      if (j.contains("version")) {
        const json& v = j["version"];
        if (!v.is_number_integer() || v.get<int64_t>() < 0 || v.get<int64_t>() > INT32_MAX)
          throw std::runtime_error("'version' must be a non-negative integer");
        next.cameraVersion = int(v.get<int64_t>());
      }
      next.restart = true;
    } else if (type == "exposure") {
      next.exposure = number(j, "value", -20.f, 20.f);
      next.toneChanged = true;
    } else if (type == "tonemap") {
      std::string v = j.at("value");
      if (v != "clamp" && v != "aces") throw std::runtime_error("tonemap must be clamp or aces");
      next.tone = v == "aces" ? ToneMap::Aces : ToneMap::Clamp;
      next.toneChanged = true;
    } else if (type == "environment") {
      if (!scene_->env) throw std::runtime_error("the scene has no environment map");
      next.envRotation = number(j, "rotation", -360.f, 360.f);
      next.envScale = number(j, "scale", 0.f, 1e4f);
      next.rebuild = true;
      ++next.sceneVersion;
    } else if (type == "strategy") {
      next.strategy = findStrategy(j.at("value").get<std::string>()).name;
      next.rebuild = true;
      ++next.sceneVersion;
    } else if (type == "integrator") {
      next.integrator = integratorName(findIntegrator(j.at("value").get<std::string>()));
      next.rebuild = true;
    } else if (type == "resolution") {
      next.resolutionScale = number(j, "scale", 0.1f, 2.f);
      next.restart = true;
    } else if (type == "adaptive") {
      // Stopping is final, so a new threshold starts the film over rather than reviving pixels.
      next.noiseThreshold = number(j, "threshold", 0.f, 10.f);
      if (j.contains("minSpp")) {
        const json& v = j["minSpp"];
        if (!v.is_number_integer() || v.get<int64_t>() < 2 || v.get<int64_t>() > 1000000)
          throw std::runtime_error("'minSpp' must be an integer in [2, 1000000]");
        next.minSpp = int(v.get<int64_t>());
      }
      next.restart = true;
    }
    *state_ = next;
  } catch (const json::exception& e) {
    throw std::runtime_error(type + ": " + e.what());
  } catch (const std::runtime_error& e) {
    std::string what = e.what();
    throw std::runtime_error(what.rfind(type, 0) == 0 ? what : type + ": " + what);
  }
  wake_.notify_all();
  return "";
}

void ViewSession::pageConnected() {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    state_->frameRequested = true;
    state_->resend = true;
  }
  wake_.notify_all();
}

void ViewSession::requestFrame() {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    state_->frameRequested = true;
  }
  wake_.notify_all();
}

std::string ViewSession::saveExr() {
  Image img;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    img = lastImage_;
  }
  if (img.width == 0) throw std::runtime_error("nothing rendered yet");
  namespace fs = std::filesystem;
  fs::path scene(scenePath_);
  fs::path dir = scene.has_parent_path() ? scene.parent_path() : fs::path(".");
  for (int n = 1; n < 100000; ++n) {
    fs::path p = dir / fmt::format("{}-view-{}.exr", scene.stem().string(), n);
    if (fs::exists(p)) continue;
    saveImage(img, p.string(), SaveOptions{});
    spdlog::info("view: saved {}", p.string());
    return p.string();
  }
  throw std::runtime_error("no free file name beside the scene");
}

ViewFrame ViewSession::makeFrame(const Image& hdr, const State& s) {
  SaveOptions so;
  so.exposure = s.exposure;
  so.toneMap = s.tone;
  ViewFrame f;
  f.jpeg = encodeJpeg(hdr.width, hdr.height, toneMapImage(hdr, so), opts_.jpegQuality);
  return f;
}

void ViewSession::run() {
  PreparedRender pr;
  std::string prIntegrator;
  // Executors of other integrators, kept while the scene stays the same, so that switching
  // back (grid while the camera moves, path when it stops) costs no new photon maps.
  std::map<std::string, PreparedRender> parked;
  int parkedVersion = 0;
  int spp = 0, sentSpp = -1, frame = 0;
  const int baseW = scene_->camera.width, baseH = scene_->camera.height;
  const Camera baseFilm = scene_->camera;  // its crop window, if any
  const Transform envBase = scene_->env ? scene_->env->options().toWorld : Transform{};
  const float envBaseScale = scene_->env ? scene_->env->options().scale : 1.f;
  auto t0 = Clock::now(), lastFrame = Clock::now();
  PassCounters counters;
  Progress quiet(1, false);
  State s;
  // Adaptive sampling, as renderPasses does it; off for an executor that cannot mask pixels (SPPM).
  ActivePixels pixels(0, 0, 0.f);
  auto limit = [&] { return pr.executor && !pixels.converged() ? std::min(opts_.maxSpp, pr.spp) : 0; };
  // Whether the page asked for a frame that differs from the one it has (under mutex_).
  auto frameWanted = [&](const State& st) {
    return st.frameRequested && (st.toneChanged || st.resend || spp != sentSpp);
  };
  while (!stop_) {
    bool restart = false, rebuild = false, send = false;
    {
      std::unique_lock<std::mutex> lock(mutex_);
      wake_.wait(lock, [&] {
        const State& st = *state_;
        return stop_ || st.restart || st.rebuild || frameWanted(st) || spp < limit();
      });
      if (stop_) break;
      restart = state_->restart;
      rebuild = state_->rebuild;
      state_->restart = state_->rebuild = false;
      s = *state_;
    }
    if (restart || rebuild) {
      Camera& cam = scene_->camera;
      cam.toWorld = lookAt(s.origin, s.target, s.up) * cameraShape_;
      cam.width = std::max(8, int(std::lround(baseW * s.resolutionScale)));
      cam.height = std::max(8, int(std::lround(baseH * s.resolutionScale)));
      if (baseFilm.filmWidth > 0) {
        // A crop window scales with the image: the film and the window's corner by as much.
        auto scaled = [](int base, int now, int was, int size) { return std::max(size, int(std::lround(double(base) * now / was))); };
        cam.filmWidth = scaled(baseFilm.filmWidth, cam.width, baseW, cam.width);
        cam.filmHeight = scaled(baseFilm.filmHeight, cam.height, baseH, cam.height);
        cam.cropX = std::min(int(std::lround(double(baseFilm.cropX) * cam.width / baseW)), cam.filmWidth - cam.width);
        cam.cropY = std::min(int(std::lround(double(baseFilm.cropY) * cam.height / baseH)), cam.filmHeight - cam.height);
      }
      try {
        if (rebuild) {
          if (scene_->env) scene_->env->setPlacement(envBaseScale * s.envScale, rotate(Vec3f(0, 1, 0), s.envRotation) * envBase);
          scene_->integrator.type = findIntegrator(s.integrator);
          // Only a new strategy resets direct's sample counts to the strategy's own; an
          // integrator or environment change keeps what the scene file set.
          if (s.strategy != scene_->integrator.env.strategy) scene_->integrator.setStrategy(s.strategy);
        }
        scene_->finalize();
        if (s.sceneVersion != parkedVersion) {
          parked.clear();
          parkedVersion = s.sceneVersion;
          if (pr.executor) pr = PreparedRender{};
        }
        if (rebuild && prIntegrator != s.integrator) {
          if (pr.executor) parked[prIntegrator] = std::move(pr);
          auto it = parked.find(s.integrator);
          pr = it != parked.end() ? std::move(it->second) : PreparedRender{};
          if (it != parked.end()) parked.erase(it);
          prIntegrator = s.integrator;
        }
        // An executor made while adaptive sampling was off keeps no variance: make it anew
        // (not SPPM's, which samples every pixel every pass and never keeps it).
        if (pr.executor && s.noiseThreshold > 0.f && scene_->integrator.type != IntegratorType::Sppm &&
            !pr.executor->keepsVariance())
          pr = PreparedRender{};
        RenderOptions ro;
        ro.progress = false;
        ro.threads = opts_.threads;
        ro.spp = opts_.maxSpp;
        ro.noiseThreshold = s.noiseThreshold;
        // Twice a large scene's resolution had resized the film past the machine's memory.
        requireFilmFits(scene_->view().camera, ro, opts_.memoryBytes > 0.0 ? opts_.memoryBytes : physicalMemoryBytes());
        if (!pr.executor || !pr.executor->restart(scene_->view().camera)) {
          auto tp = Clock::now();
          pr = PreparedRender{};  // free the old executor's maps first
          pr = opts_.prepare ? opts_.prepare(*scene_, *accel_, ro) : prepareRender(*scene_, *accel_, ro);
          ++preparations_;
          spdlog::info("view: {} ready in {:.2f} s", s.integrator,
                       std::chrono::duration<double>(Clock::now() - tp).count());
        }
        pixels = ActivePixels(scene_->camera.width, scene_->camera.height, s.noiseThreshold);
        pixels.attach(*pr.executor);
      } catch (const std::exception& e) {
        // Any failure (a bad setting, memory for a huge film) ends this render, not the viewer.
        spdlog::warn("view: {}", e.what());
        pr = PreparedRender{};
        prIntegrator.clear();
        pixels = ActivePixels(0, 0, 0.f);
        if (sink_) sink_(ViewFrame{json{{"type", "error"}, {"message", e.what()}}.dump(), ""});
      }
      spp = 0;
      sentSpp = -1;
      t0 = Clock::now();
    }
    if (spp < limit()) {
      pr.executor->runPass(spp, spp + 1, quiet, &counters);
      ++spp;
      pixels.passDone(spp - 1, spp);
      // Every 4 passes from the minimum on: each check reads the film back (from a GPU too).
      if (pixels.adaptive() && spp >= s.minSpp && (spp - s.minSpp) % 4 == 0 && spp < limit()) {
        FilmSums film;
        pixels.update(*pr.executor, &film);
      }
    }
    {
      std::lock_guard<std::mutex> lock(mutex_);
      send = pr.executor && frameWanted(*state_);
      if (send) {
        state_->frameRequested = false;
        state_->toneChanged = false;
        state_->resend = false;
        // Only the tone settings: a camera or integrator that arrived since is not what this
        // film holds, and the frame must not claim it.
        s.exposure = state_->exposure;
        s.tone = state_->tone;
      }
    }
    if (!send) continue;
    FilmSums film;
    pr.executor->readFilm(&film);
    const Camera& cam = scene_->view().camera;
    Image img = filmMean(film, cam.width, cam.height, pixels.samples());
    ViewFrame f = makeFrame(img, s);
    auto now = Clock::now();
    double seconds = std::chrono::duration<double>(now - t0).count();
    double sinceLast = std::chrono::duration<double>(now - lastFrame).count();
    lastFrame = now;
    f.meta = json{{"type", "frame"},
                  {"frame", ++frame},
                  {"spp", spp},
                  {"seconds", seconds},
                  {"fps", sinceLast > 0 ? 1.0 / sinceLast : 0.0},
                  {"width", cam.width},
                  {"height", cam.height},
                  {"exposure", s.exposure},
                  {"tonemap", s.tone == ToneMap::Aces ? "aces" : "clamp"},
                  {"cameraVersion", s.cameraVersion},
                  {"integrator", s.integrator},
                  {"strategy", s.strategy},
                  {"adaptive", pixels.adaptive()},
                  {"noiseThreshold", s.noiseThreshold},
                  {"sampling", double(pixels.activeCount()) / double(std::max<size_t>(1, pixels.pixelCount()))},
                  {"converged", pixels.converged()},
                  {"meanSpp", pixels.meanSamples()},
                  {"bytes", f.jpeg.size()}}
                 .dump();
    {
      std::lock_guard<std::mutex> lock(mutex_);
      lastImage_ = std::move(img);
    }
    sentSpp = spp;
    ++framesSent_;
    if (sink_) sink_(std::move(f));
  }
}

}  // namespace envgi
