// The viewer's orbiting case as the page drives it: a ViewSession on a scene, the camera
// turned a little about the target, then "next" until a frame from that camera arrives. Each
// move returns its time from the camera message to that frame (render, tone map, JPEG).
#pragma once

#include <chrono>
#include <cmath>
#include <condition_variable>
#include <memory>
#include <mutex>
#include <nlohmann/json.hpp>
#include <string>

#include "scene/SceneLoader.h"
#include "view/ViewSession.h"

namespace envgi::bench {

class ViewOrbit {
 public:
  // vo.maxSpp = 1 is the orbiting case: one sample a pixel per camera.
  ViewOrbit(const std::string& scenePath, int res, const std::string& integrator, ViewOptions vo) {
    using json = nlohmann::json;
    auto scene = std::make_unique<Scene>();
    loadScene(scenePath, {{"res", std::to_string(res)}}, *scene);
    session_ = std::make_unique<ViewSession>(std::move(scene), scenePath, vo);
    session_->start([this](ViewFrame f) {
      json m = json::parse(f.meta);
      if (m["type"] != "frame") return;
      std::lock_guard<std::mutex> l(m_);
      lastVersion_ = m["cameraVersion"];
      lastIntegrator_ = m["integrator"];
      bytes_ = f.jpeg.size();
      cv_.notify_all();
    });
    json hello = json::parse(session_->hello());
    integrator_ = integrator;
    session_->handle(json{{"type", "integrator"}, {"value", integrator}}.dump());
    std::vector<float> o = hello["camera"]["origin"], t = hello["camera"]["target"], up = hello["camera"]["up"];
    origin_ = o;
    target_ = t;
    up_ = up;
    moveAndWait();  // the integrator's preparation (grid: photons and the grid) is not timed
  }
  ~ViewOrbit() { session_->stop(); }

  // One camera move; milliseconds until the first frame from the new camera.
  double moveAndWait() {
    using json = nlohmann::json;
    auto t0 = std::chrono::steady_clock::now();
    ++version_;
    float dx = origin_[0] - target_[0], dz = origin_[2] - target_[2];
    float a = 0.02f * float(version_), c = std::cos(a), s = std::sin(a);
    json cam = {{"type", "camera"},
                {"origin", {target_[0] + c * dx - s * dz, origin_[1], target_[2] + s * dx + c * dz}},
                {"target", target_},
                {"up", up_},
                {"version", version_}};
    session_->handle(cam.dump());
    // As the page does: ask for the next frame after each one, until one shows this camera.
    std::unique_lock<std::mutex> l(m_);
    while (!(lastVersion_ == version_ && lastIntegrator_ == integrator_)) {
      l.unlock();
      session_->requestFrame();
      l.lock();
      cv_.wait_for(l, std::chrono::milliseconds(2));
    }
    return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
  }
  size_t lastJpegBytes() const { return bytes_; }

 private:
  std::unique_ptr<ViewSession> session_;
  std::mutex m_;
  std::condition_variable cv_;
  int lastVersion_ = -1, version_ = 0;
  std::string lastIntegrator_, integrator_;
  size_t bytes_ = 0;
  std::vector<float> origin_, target_, up_;
};

}  // namespace envgi::bench
