// What `envgi view` renders: one scene, progressively, on a worker thread, steered by the
// page's messages (camera, exposure, tone curve, environment, strategy, integrator,
// resolution, noise threshold, pause, cancel, save). Frames go out tone-mapped as JPEG, at
// most one in flight: the page asks for the next when it has shown the last, so a slow link
// never backs up the renderer. A camera move cuts the pass in flight and starts coarse (half
// the resolution) for its first frame, as Cycles' viewport does; the film refines after it.
#pragma once

#include <atomic>
#include <condition_variable>
#include <filesystem>
#include <functional>
#include <memory>
#include <mutex>
#include <nlohmann/json_fwd.hpp>
#include <string>
#include <vector>
#include <thread>

#include "accel/EmbreeAccel.h"
#include "image/Image.h"
#include "render/Renderer.h"
#include "scene/Scene.h"

namespace envgi {

struct ViewFrame {
  std::string meta;  // JSON: frame number, spp, seconds, size, exposure, camera version...
  std::string jpeg;
};

struct ViewOptions {
  // Makes the executor for the scene's integrator; unset: prepareRender on the CPU (Embree).
  // `envgi view` sets it to the GPU's where one is used.
  std::function<PreparedRender(const Scene&, const EmbreeAccel&, const RenderOptions&)> prepare;
  int threads = 0;
  int maxSpp = 4096;  // stop refining here
  // Adaptive sampling at start (the page can change it): a pixel stops refining once it and its
  // neighbours are below this noise (AdaptiveSampling.h); 0: off.
  float noiseThreshold = 0.f;
  int adaptiveMinSpp = 16;
  int jpegQuality = 85;
  // A camera move's first frame at half the resolution, then the full film (Cycles' start
  // resolution): a move costs a quarter of the pixels until the page has seen it.
  bool coarseMoves = true;
  // Loads the scene file anew (with the command line's -D values and overrides). Set: the
  // session watches the file and reloads it when it changes, keeping the page's camera unless
  // the file's camera changed. Files the scene names (meshes, maps) are not watched.
  std::function<std::unique_ptr<Scene>()> reload;
  // Files "save" may write in one session (each a full-size EXR and PNG).
  int maxSaves = 100;
  // The memory a film must fit in half of (requireFilmFits); 0: this machine's. A restart at
  // another resolution resizes the film without prepareRender, so the session checks it itself.
  double memoryBytes = 0.0;
};

// The page's false-colour view: each pixel's log2 luminance (plus exposure) as a colour ramp,
// -8 stops dark blue to +8 stops red, 8-bit RGB.
std::vector<unsigned char> falseColorImage(const Image& hdr, float exposure);

class ViewSession {
 public:
  // Takes a loaded (not yet finalised) scene; scenePath says where "save" writes.
  ViewSession(std::unique_ptr<Scene> scene, std::string scenePath, ViewOptions opts);
  ~ViewSession();
  ViewSession(const ViewSession&) = delete;
  ViewSession& operator=(const ViewSession&) = delete;

  // Frames are handed to sink on the worker thread.
  void start(std::function<void(ViewFrame)> sink);
  void stop();

  // The first message a page gets: scene, camera, choices, current state (JSON).
  std::string hello() const;
  // One message from the page (JSON). Returns the reply to send (JSON, possibly empty);
  // throws std::runtime_error for a malformed message, leaving the state as it was.
  std::string handle(const std::string& message);
  // The page showed the last frame and wants the next.
  void requestFrame();
  // A page connected: it gets the current frame, even when the render has finished (its
  // samples or adaptive sampling's threshold reached) and an earlier page had that frame.
  void pageConnected();

  int framesSent() const { return framesSent_.load(); }
  // Waits until the worker has taken every change handed to it so far (a new camera built, an
  // executor prepared or its failure reported); false if it has not after `seconds`.
  bool waitForWorker(double seconds);
  // Renders that ended in an exception escaping the render loop (each reported to the page);
  // none is expected: every known failure is an error reply or an error frame.
  int renderFailures() const { return renderFailures_.load(); }
  // How many executors were made (photon maps, grids...): switching back to an integrator
  // used before, with the same environment and strategy, makes none.
  int preparations() const { return preparations_.load(); }
  // Writes the current film beside the scene (atomically) as EXR, with how it was made in its
  // header, and as PNG as the page shows it; returns the EXR's path. Saving the same film
  // twice writes nothing new.
  std::string saveExr();
  // Saves written so far (files beside the scene, EXR and PNG counted once).
  int savesWritten() const { return savesWritten_.load(); }

 private:
  struct State;
  void run();
  // Renders until stop (false) or until the scene file changed (true: reload, then again).
  bool renderLoop();
  void adopt(std::unique_ptr<Scene> scene);  // a loaded scene, its BVH and its camera
  bool sceneFileChanged();
  void reloadScene();
  ViewFrame makeFrame(const Image& hdr, const State& s);
  std::string pixelValue(const nlohmann::json& message);

  std::unique_ptr<Scene> scene_;
  std::string scenePath_;
  std::string sceneHash_;  // of the scene file's bytes, written into saved images
  std::filesystem::file_time_type sceneFileTime_{};  // when the file adopted was written
  ViewOptions opts_;
  std::unique_ptr<EmbreeAccel> accel_;
  // What the scene's to_world does before its rigid frame (an orthographic camera's scale,
  // which sizes its view), kept when the page moves the camera.
  Transform cameraShape_;
  std::unique_ptr<State> state_;  // guarded by mutex_
  mutable std::mutex mutex_;
  std::mutex saveMutex_;  // one save at a time (taken before mutex_)
  std::condition_variable wake_;
  std::condition_variable taken_;  // the worker took the changes up to changesTaken_
  uint64_t changesGiven_ = 0, changesTaken_ = 0;  // guarded by mutex_
  std::function<void(ViewFrame)> sink_;
  std::thread worker_;
  std::atomic<bool> stop_{false};
  std::atomic<int> framesSent_{0};
  std::atomic<int> preparations_{0};
  std::atomic<int> savesWritten_{0};
  std::atomic<int> renderFailures_{0};
  // Set by a change that makes the pass in flight useless (camera, resolution...): the CPU
  // executor starts no further tile. Cleared when the worker takes the change.
  std::atomic<bool> cutPass_{false};
  // Set by a new integrator, strategy or environment, a cancel, or stop: photon maps and grids
  // being prepared stop (RenderCancelled).
  std::atomic<bool> cutPrepare_{false};
  // The mean so far and what it is, for save (guarded by mutex_).
  Image lastImage_;
  std::vector<std::pair<std::string, std::string>> lastImageAttributes_;
  std::string lastSaved_;  // the EXR written for lastImage_, if any
};

}  // namespace envgi
