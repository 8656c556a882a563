#include "view/ViewSession.h"

#include <spdlog/spdlog.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
#include <map>
#include <nlohmann/json.hpp>

#include "core/PhysicalMemory.h"
#include "render/ActivePixels.h"
#include "render/Cancellation.h"
#include "scene/NameTables.h"

namespace envgi {

using json = nlohmann::json;
using Clock = std::chrono::steady_clock;

struct ViewSession::State {
  Vec3f origin, target, up;
  int cameraVersion = 0;
  float exposure = 0.f;
  ToneMap tone = ToneMap::Clamp;
  bool falseColor = false;  // luminance as colour, in place of the tone curve
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
  bool paused = false;  // no further passes until resumed
  std::string readyIntegrator;  // the last integrator prepared in full: what "cancel" returns to
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
// A camera the worker can build: the same lookAt it calls (so no check is looser than the
// camera's own), with origin and target within 10^4 scene sizes of the scene, where a ray's
// float arithmetic still means something.
void checkCamera(Vec3f origin, Vec3f target, Vec3f up, const SceneView& sc) {
  const Vec3f centre = (sc.boundsMin + sc.boundsMax) * 0.5f;
  const float reach = 1e4f * std::max(1.f, length(sc.boundsMax - sc.boundsMin));
  if (!(length(origin - centre) <= reach && length(target - centre) <= reach))
    throw std::runtime_error(fmt::format("camera: origin and target must lie within {:g} of the scene", reach));
  if (!(length(target - origin) >= 1e-6f * reach / 1e4f))
    throw std::runtime_error("camera: origin and target must be apart");
  if (!(length(up) <= 1e30f)) throw std::runtime_error("camera: 'up' is too long");
  Transform t = lookAt(origin, target, up);
  for (const auto& row : t.mat.m)
    for (float v : row)
      if (!std::isfinite(v)) throw std::runtime_error("camera: origin, target and up must span a frame");
}
float number(const json& j, const char* key, float lo, float hi) {
  // Compared as floats, the precision the bounds and the state are kept in: 0.1 is in [0.1, 2].
  double d = j.at(key).get<double>();
  float v = std::fabs(d) <= 3.0e38 ? float(d) : std::numeric_limits<float>::quiet_NaN();
  if (!(v >= lo && v <= hi)) throw std::runtime_error(fmt::format("'{}' must be in [{}, {}]", key, lo, hi));
  return v;
}

// FNV-1a over the file's bytes, in hex: which scene a saved image came from.
std::string fileHash(const std::string& path) {
  std::ifstream f(path, std::ios::binary);
  uint64_t h = 1469598103934665603ull;
  char c;
  while (f.get(c)) h = (h ^ uint8_t(c)) * 1099511628211ull;
  return fmt::format("{:016x}", h);
}

std::filesystem::file_time_type modifiedTime(const std::string& path) {
  std::error_code ec;
  auto t = std::filesystem::last_write_time(path, ec);
  return ec ? std::filesystem::file_time_type{} : t;
}
}  // namespace

ViewSession::ViewSession(std::unique_ptr<Scene> scene, std::string scenePath, ViewOptions opts)
    : scenePath_(std::move(scenePath)), opts_(opts), state_(std::make_unique<State>()) {
  adopt(std::move(scene));
  sceneFileTime_ = modifiedTime(scenePath_);
  State& s = *state_;
  s.strategy = scene_->integrator.env.strategy;
  s.integrator = integratorName(scene_->integrator.type);
  s.noiseThreshold = opts_.noiseThreshold;
  s.minSpp = opts_.adaptiveMinSpp;
}

void ViewSession::adopt(std::unique_ptr<Scene> scene) {
  scene->finalize();
  auto accel = std::make_unique<EmbreeAccel>(*scene);
  // The camera the file sets, as origin, target and up: the page's camera unless the file's
  // own camera changed since the last one adopted.
  const Transform& t = scene->camera.toWorld;
  Vec3f origin = t.point(Vec3f(0.f));
  Vec3f fwd = normalize(t.vector(Vec3f(0.f, 0.f, 1.f)));
  const SceneView& sc = scene->view();
  Vec3f centre = (sc.boundsMin + sc.boundsMax) * 0.5f;
  float dist = std::max(dot(centre - origin, fwd), 1e-2f * length(sc.boundsMax - sc.boundsMin) + 1e-3f);
  Vec3f target = origin + fwd * dist, up = normalize(t.vector(Vec3f(0.f, 1.f, 0.f)));
  std::string hash = fileHash(scenePath_);  // read before the lock: the page's messages wait on it
  std::lock_guard<std::mutex> lock(mutex_);
  const bool fileCameraChanged = !scene_ || std::memcmp(&scene_->camera.toWorld.mat, &t.mat, sizeof t.mat) != 0;
  scene_ = std::move(scene);
  accel_ = std::move(accel);
  sceneHash_ = std::move(hash);
  cameraShape_ = scene_->camera.orthographic ? lookAt(origin, target, up).inverse() * t : Transform{};
  if (fileCameraChanged) {
    state_->origin = origin;
    state_->target = target;
    state_->up = up;
  }
}

ViewSession::~ViewSession() { stop(); }

void ViewSession::start(std::function<void(ViewFrame)> sink) {
  sink_ = std::move(sink);
  worker_ = std::thread([this] { run(); });
}

void ViewSession::stop() {
  stop_ = true;
  cutPass_ = true;
  cutPrepare_ = true;
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
            {"targetSpp", opts_.maxSpp},
            {"paused", s.paused},
            {"hasEnvironment", scene_->env != nullptr}};
  return j.dump();
}

std::string ViewSession::handle(const std::string& message) {
  json j = json::parse(message, nullptr, false);
  if (j.is_discarded() || !j.is_object() || !j.contains("type") || !j["type"].is_string())
    throw std::runtime_error("malformed message (not a JSON object with a 'type')");
  std::string type = j["type"];
  static const char* known[] = {"next",       "save",       "camera",   "exposure", "tonemap", "environment",
                                "strategy",   "integrator", "resolution", "adaptive", "pause",   "cancel",
                                "pixel"};
  if (std::find(std::begin(known), std::end(known), type) == std::end(known))
    throw std::runtime_error("unknown message type '" + type + "'");
  try {
    if (type == "next") {
      requestFrame();
      return "";
    }
    if (type == "save") return json{{"type", "saved"}, {"path", saveExr()}}.dump();
    if (type == "pixel") return pixelValue(j);
    std::lock_guard<std::mutex> lock(mutex_);
    State next = *state_;
    if (type == "camera") {
      next.origin = vec3(j, "origin");
      next.target = vec3(j, "target");
      next.up = vec3(j, "up");
      checkCamera(next.origin, next.target, next.up, scene_->view());
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
      if (v != "clamp" && v != "aces" && v != "falsecolor")
        throw std::runtime_error("tonemap must be clamp, aces or falsecolor");
      next.falseColor = v == "falsecolor";
      if (!next.falseColor) next.tone = v == "aces" ? ToneMap::Aces : ToneMap::Clamp;
      next.toneChanged = true;
    } else if (type == "environment") {
      if (!scene_->env) throw std::runtime_error("the scene has no environment map");
      next.envRotation = number(j, "rotation", -360.f, 360.f);
      next.envScale = number(j, "scale", 0.f, 1e4f);
      next.rebuild = true;
      ++next.sceneVersion;
    } else if (type == "strategy") {
      if (!scene_->env) throw std::runtime_error("the scene has no environment map");
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
    } else if (type == "pause") {
      const json& v = j.at("value");
      if (!v.is_boolean()) throw std::runtime_error("'value' must be true or false");
      next.paused = v.get<bool>();
      next.toneChanged = true;  // a frame that says so, even of a film that no longer refines
    } else if (type == "cancel") {
      // Stops a preparation (photon maps, a grid) and returns to the integrator ready before.
      cutPrepare_ = true;
      if (!next.readyIntegrator.empty() && next.readyIntegrator != next.integrator) {
        next.integrator = next.readyIntegrator;
        next.rebuild = true;
      }
    }
    if (next.rebuild) cutPrepare_ = true;
    if (next.restart || next.rebuild) {
      cutPass_ = true;
      ++changesGiven_;
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

bool ViewSession::waitForWorker(double seconds) {
  std::unique_lock<std::mutex> lock(mutex_);
  const uint64_t given = changesGiven_;
  return taken_.wait_for(lock, std::chrono::duration<double>(seconds),
                         [&] { return changesTaken_ >= given || stop_; });
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
  // Under the lock throughout: two saves at once must not both find the same free name.
  std::lock_guard<std::mutex> lock(saveMutex_);
  Image img;
  std::vector<std::pair<std::string, std::string>> attributes;
  {
    std::lock_guard<std::mutex> state(mutex_);
    if (!lastSaved_.empty()) return lastSaved_;
    img = lastImage_;
    attributes = lastImageAttributes_;
  }
  if (img.width == 0) throw std::runtime_error("nothing rendered yet");
  if (savesWritten_ >= opts_.maxSaves)
    throw std::runtime_error(fmt::format("this session has saved {} images, its limit; restart envgi view to save more",
                                         opts_.maxSaves));
  namespace fs = std::filesystem;
  fs::path scene(scenePath_);
  fs::path dir = scene.has_parent_path() ? scene.parent_path() : fs::path(".");
  // Past any name left by earlier sessions; the limit above bounds what this one adds.
  for (int n = 1; n <= opts_.maxSaves + 10000; ++n) {
    fs::path p = dir / fmt::format("{}-view-{}.exr", scene.stem().string(), n);
    fs::path png = fs::path(p).replace_extension(".png");
    if (fs::exists(p) || fs::exists(png)) continue;
    SaveOptions so;
    so.exrAttributes = attributes;
    saveImage(img, p.string(), so);
    {
      std::lock_guard<std::mutex> state(mutex_);
      so.exposure = state_->exposure;
      so.toneMap = state_->tone;
    }
    saveImage(img, png.string(), so);
    ++savesWritten_;
    spdlog::info("view: saved {} and {}", p.string(), png.filename().string());
    std::lock_guard<std::mutex> state(mutex_);
    // Only if the film did not change meanwhile.
    if (lastImage_.width == img.width && lastImage_.rgb == img.rgb) lastSaved_ = p.string();
    return p.string();
  }
  throw std::runtime_error("no free file name beside the scene");
}

std::string ViewSession::pixelValue(const json& j) {
  auto coordinate = [&](const char* key) {
    const json& v = j.at(key);
    if (!v.is_number_integer()) throw std::runtime_error(std::string("'") + key + "' must be an integer");
    return v.get<int64_t>();
  };
  const int64_t x = coordinate("x"), y = coordinate("y");
  std::lock_guard<std::mutex> lock(mutex_);
  if (lastImage_.width == 0) throw std::runtime_error("nothing rendered yet");
  if (x < 0 || y < 0 || x >= lastImage_.width || y >= lastImage_.height)
    throw std::runtime_error(fmt::format("({}, {}) is outside the {} x {} film", x, y, lastImage_.width, lastImage_.height));
  const float* p = &lastImage_.rgb[3 * (size_t(y) * size_t(lastImage_.width) + size_t(x))];
  Color c(p[0], p[1], p[2]);
  return json{{"type", "pixel"}, {"x", x}, {"y", y}, {"rgb", {c.x, c.y, c.z}}, {"luminance", luminance(c)}}.dump();
}

std::vector<unsigned char> falseColorImage(const Image& hdr, float exposure) {
  // log2 luminance from -8 to +8 stops about the exposure, blue through green to red (tev's
  // and Blender's "False Color" read the same way: each colour a band of stops).
  static const float ramp[5][3] = {{0.f, 0.f, 0.5f}, {0.f, 0.6f, 1.f}, {0.1f, 0.9f, 0.1f}, {1.f, 0.9f, 0.f}, {1.f, 0.f, 0.f}};
  const size_t n = size_t(hdr.width) * size_t(hdr.height);
  std::vector<unsigned char> out(3 * n);
  for (size_t i = 0; i < n; ++i) {
    const float lum = luminance(Color(hdr.rgb[3 * i], hdr.rgb[3 * i + 1], hdr.rgb[3 * i + 2]));
    const float stops = lum > 0.f ? std::log2(lum) + exposure : -8.f;
    const float t = std::clamp((stops + 8.f) / 16.f, 0.f, 1.f) * 4.f;
    const int k = std::min(3, int(t));
    const float f = t - float(k);
    for (int c = 0; c < 3; ++c)
      out[3 * i + size_t(c)] = (unsigned char)std::lround(255.f * (ramp[k][c] * (1.f - f) + ramp[k + 1][c] * f));
  }
  return out;
}

ViewFrame ViewSession::makeFrame(const Image& hdr, const State& s) {
  SaveOptions so;
  so.exposure = s.exposure;
  so.toneMap = s.tone;
  ViewFrame f;
  f.jpeg = encodeJpeg(hdr.width, hdr.height, s.falseColor ? falseColorImage(hdr, s.exposure) : toneMapImage(hdr, so),
                      opts_.jpegQuality);
  return f;
}

namespace {
// Integrators that build something before their first pass (photon maps, a grid), which the
// page shows as a state of its own.
bool prepares(const std::string& integrator) { return integrator == "photon" || integrator == "grid" || integrator == "sppm"; }

std::string statusMessage(const std::string& state, const std::string& message) {
  return json{{"type", "status"}, {"state", state}, {"message", message}}.dump();
}
}  // namespace

void ViewSession::run() {
  while (!stop_) {
    try {
      if (!renderLoop()) return;
      reloadScene();
      continue;
    } catch (const std::exception& e) {
      // Nothing the page sends may end the process: the viewer says why this render stopped
      // and waits for the next change.
      ++renderFailures_;
      spdlog::error("view: the render stopped: {}", e.what());
      if (sink_) sink_(ViewFrame{json{{"type", "error"}, {"message", std::string("the render stopped: ") + e.what()}}.dump(), ""});
      {
        std::lock_guard<std::mutex> lock(mutex_);
        changesTaken_ = changesGiven_;
      }
      taken_.notify_all();
    }
  }
}

bool ViewSession::sceneFileChanged() {
  if (!opts_.reload) return false;
  auto t = modifiedTime(scenePath_);
  if (t == sceneFileTime_) return false;
  sceneFileTime_ = t;
  return true;
}

void ViewSession::reloadScene() {
  std::unique_ptr<Scene> scene;
  try {
    scene = opts_.reload();
  } catch (const std::exception& e) {
    // A half-edited file: say why, keep rendering the scene as it was.
    spdlog::warn("view: the scene file changed but does not load: {}", e.what());
    if (sink_) sink_(ViewFrame{json{{"type", "error"}, {"message", std::string("scene not reloaded: ") + e.what()}}.dump(), ""});
  }
  const bool reloaded = scene != nullptr;
  if (reloaded) {
    adopt(std::move(scene));
    spdlog::info("view: reloaded {}", scenePath_);
  }
  {
    std::lock_guard<std::mutex> lock(mutex_);
    state_->restart = state_->rebuild = true;
    ++state_->sceneVersion;
    state_->frameRequested = true;
    state_->resend = true;
  }
  if (reloaded && sink_) {
    json hi = json::parse(hello());
    hi["reloaded"] = true;
    sink_(ViewFrame{hi.dump(), ""});
  }
}

bool ViewSession::renderLoop() {
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
  int filmCamera = -1;   // the camera version the film was started for
  bool coarse = false;   // the film is a move's first, at half the resolution
  bool refine = false;   // the coarse frame went out: start the full film
  // Adaptive sampling, as renderPasses does it; off for an executor that cannot mask pixels (SPPM).
  ActivePixels pixels(0, 0, 0.f);
  auto limit = [&](bool paused) { return pr.executor && !pixels.converged() && !paused ? std::min(opts_.maxSpp, pr.spp) : 0; };
  // Whether the page asked for a frame that differs from the one it has (under mutex_).
  auto frameWanted = [&](const State& st) {
    return st.frameRequested && (st.toneChanged || st.resend || spp != sentSpp);
  };
  auto lastFileCheck = Clock::now();
  while (!stop_) {
    // The scene file, twice a second: a change ends this loop (its executors hold the old
    // scene) and run() reloads.
    if (opts_.reload && Clock::now() - lastFileCheck > std::chrono::milliseconds(500)) {
      lastFileCheck = Clock::now();
      if (sceneFileChanged()) return true;
    }
    bool restart = refine, rebuild = false, send = false;
    uint64_t takenNow = 0;
    {
      std::unique_lock<std::mutex> lock(mutex_);
      const bool ready = wake_.wait_for(lock, std::chrono::milliseconds(500), [&] {
        const State& st = *state_;
        return stop_ || restart || st.restart || st.rebuild || frameWanted(st) || spp < limit(st.paused);
      });
      if (stop_) break;
      if (!ready) continue;
      refine = false;
      restart = restart || state_->restart;
      rebuild = state_->rebuild;
      state_->restart = state_->rebuild = false;
      takenNow = changesGiven_;
      cutPass_ = false;
      if (rebuild) cutPrepare_ = false;
      s = *state_;
    }
    if (restart || rebuild) {
      // A move's first film is coarse; a refinement, a rebuild or any other change is full size.
      coarse = opts_.coarseMoves && !rebuild && filmCamera >= 0 && s.cameraVersion != filmCamera;
      filmCamera = s.cameraVersion;
      const float scale = s.resolutionScale * (coarse ? 0.5f : 1.f);
      try {
        Camera& cam = scene_->camera;
        cam.toWorld = lookAt(s.origin, s.target, s.up) * cameraShape_;
        cam.width = std::max(8, int(std::lround(baseW * scale)));
        cam.height = std::max(8, int(std::lround(baseH * scale)));
        if (baseFilm.filmWidth > 0) {
          // A crop window scales with the image: the film and the window's corner by as much.
          auto scaled = [](int base, int now, int was, int size) { return std::max(size, int(std::lround(double(base) * now / was))); };
          cam.filmWidth = scaled(baseFilm.filmWidth, cam.width, baseW, cam.width);
          cam.filmHeight = scaled(baseFilm.filmHeight, cam.height, baseH, cam.height);
          cam.cropX = std::min(int(std::lround(double(baseFilm.cropX) * cam.width / baseW)), cam.filmWidth - cam.width);
          cam.cropY = std::min(int(std::lround(double(baseFilm.cropY) * cam.height / baseH)), cam.filmHeight - cam.height);
        }
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
        ro.cancel = &cutPrepare_;
        // Twice a large scene's resolution had resized the film past the machine's memory.
        requireFilmFits(scene_->view().camera, ro, opts_.memoryBytes > 0.0 ? opts_.memoryBytes : physicalMemoryBytes());
        if (!pr.executor || !pr.executor->restart(scene_->view().camera)) {
          auto tp = Clock::now();
          pr = PreparedRender{};  // free the old executor's maps first
          const bool announce = prepares(s.integrator);
          if (announce && sink_) sink_(ViewFrame{statusMessage("preparing", "preparing " + s.integrator + "..."), ""});
          pr = opts_.prepare ? opts_.prepare(*scene_, *accel_, ro) : prepareRender(*scene_, *accel_, ro);
          ++preparations_;
          const double secs = std::chrono::duration<double>(Clock::now() - tp).count();
          spdlog::info("view: {} ready in {:.2f} s", s.integrator, secs);
          if (announce && sink_)
            sink_(ViewFrame{statusMessage("ready", fmt::format("{} ready in {:.2f} s", s.integrator, secs)), ""});
        }
        pixels = ActivePixels(scene_->camera.width, scene_->camera.height, s.noiseThreshold);
        pixels.attach(*pr.executor);
        std::lock_guard<std::mutex> lock(mutex_);
        state_->readyIntegrator = s.integrator;
      } catch (const RenderCancelled&) {
        // A newer choice (or stop) interrupted the preparation: the loop takes that choice next.
        spdlog::info("view: preparing {} was cancelled", s.integrator);
        pr = PreparedRender{};
        prIntegrator.clear();
        pixels = ActivePixels(0, 0, 0.f);
        if (sink_) sink_(ViewFrame{statusMessage("cancelled", "preparing " + s.integrator + " was cancelled"), ""});
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
      {
        std::lock_guard<std::mutex> lock(mutex_);
        changesTaken_ = std::max(changesTaken_, takenNow);
      }
      taken_.notify_all();
    }
    if (spp < limit(s.paused)) {
      try {
        // A film's first pass is never cut: a stream of moves faster than a pass would
        // otherwise cut every pass and show nothing until the moves stop.
        pr.executor->watchCancel(spp == 0 ? nullptr : &cutPass_);
        pr.executor->runPass(spp, spp + 1, quiet, &counters);
      } catch (const RenderCancelled&) {
        continue;  // a pass that prepares as it goes (SPPM's photons) stopped for a change
      }
      // Cut for a change the loop takes next: this film is not going to be shown.
      if (pr.executor->cutPass()) continue;
      ++spp;
      pixels.passDone(spp - 1, spp);
      // Every 4 passes from the minimum on: each check reads the film back (from a GPU too).
      if (pixels.adaptive() && spp >= s.minSpp && (spp - s.minSpp) % 4 == 0 && spp < limit(s.paused)) {
        FilmSums film;
        pixels.update(*pr.executor, &film);
      }
    }
    {
      std::lock_guard<std::mutex> lock(mutex_);
      // A film from a camera already replaced is not encoded (the next one is due), unless it
      // is that film's first frame: while the camera keeps moving, each move's first pass shows.
      const bool replaced = state_->restart || state_->rebuild;
      send = pr.executor && frameWanted(*state_) && (!replaced || (sentSpp < 0 && spp > 0 && !state_->rebuild));
      if (send) {
        state_->frameRequested = false;
        state_->toneChanged = false;
        state_->resend = false;
        // Only the tone settings: a camera or integrator that arrived since is not what this
        // film holds, and the frame must not claim it.
        s.exposure = state_->exposure;
        s.tone = state_->tone;
        s.falseColor = state_->falseColor;
        s.paused = state_->paused;
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
                  {"targetSpp", std::min(opts_.maxSpp, pr.spp)},
                  {"paused", s.paused},
                  {"coarse", coarse},
                  {"seconds", seconds},
                  // The rate since the previous frame; none for the first, which has no previous.
                  {"fps", frame > 1 && sinceLast > 0 ? 1.0 / sinceLast : 0.0},
                  {"width", cam.width},
                  {"height", cam.height},
                  {"exposure", s.exposure},
                  {"tonemap", s.falseColor ? "falsecolor" : s.tone == ToneMap::Aces ? "aces" : "clamp"},
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
      lastSaved_.clear();
      lastImageAttributes_ = {
          {"envgi:scene", scenePath_},
          {"envgi:sceneHash", sceneHash_},
          {"envgi:integrator", s.integrator},
          {"envgi:strategy", s.strategy},
          {"envgi:spp", std::to_string(spp)},
          {"envgi:camera", fmt::format("origin {} {} {} target {} {} {} up {} {} {}", s.origin.x, s.origin.y, s.origin.z,
                                       s.target.x, s.target.y, s.target.z, s.up.x, s.up.y, s.up.z)},
          {"envgi:environment", fmt::format("rotation {} scale {}", s.envRotation, s.envScale)}};
    }
    sentSpp = spp;
    ++framesSent_;
    if (sink_) sink_(std::move(f));
    // The page has seen the move: the full film takes over from the coarse one.
    if (coarse) refine = true;
  }
  return false;
}

}  // namespace envgi
