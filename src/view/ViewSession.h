// What `envgi view` renders: one scene, progressively, on a worker thread, steered by the
// page's messages (camera, exposure, tone curve, environment, strategy, integrator,
// resolution, noise threshold, save). Frames go out tone-mapped as JPEG, at most one in flight: the page asks
// for the next when it has shown the last, so a slow link never backs up the renderer.
#pragma once

#include <atomic>
#include <condition_variable>
#include <functional>
#include <memory>
#include <mutex>
#include <string>
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
  // The memory a film must fit in half of (requireFilmFits); 0: this machine's. A restart at
  // another resolution resizes the film without prepareRender, so the session checks it itself.
  double memoryBytes = 0.0;
};

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
  // How many executors were made (photon maps, grids...): switching back to an integrator
  // used before, with the same environment and strategy, makes none.
  int preparations() const { return preparations_.load(); }
  // Writes the current image beside the scene (atomically); returns its path.
  std::string saveExr();

 private:
  struct State;
  void run();
  ViewFrame makeFrame(const Image& hdr, const State& s);

  std::unique_ptr<Scene> scene_;
  std::string scenePath_;
  ViewOptions opts_;
  std::unique_ptr<EmbreeAccel> accel_;
  // What the scene's to_world does before its rigid frame (an orthographic camera's scale,
  // which sizes its view), kept when the page moves the camera.
  Transform cameraShape_;
  std::unique_ptr<State> state_;  // guarded by mutex_
  mutable std::mutex mutex_;
  std::condition_variable wake_;
  std::function<void(ViewFrame)> sink_;
  std::thread worker_;
  std::atomic<bool> stop_{false};
  std::atomic<int> framesSent_{0};
  std::atomic<int> preparations_{0};
  Image lastImage_;  // the mean so far, for save (guarded by mutex_)
};

}  // namespace envgi
