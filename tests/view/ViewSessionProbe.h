// The viewer's session driven from a test without a browser: a small ball scene's session, a
// sink that collects its frames, and a wait for the frame that satisfies a condition. Shared by
// the viewer's tests and the GPU's.
#pragma once

#include <gtest/gtest.h>

#include <chrono>
#include <condition_variable>
#include <memory>
#include <mutex>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "scene/SceneLoader.h"
#include "support/SmallGrid.h"
#include "view/BallScene.h"
#include "view/ViewSession.h"

namespace envgi::test {

// Collects what the session hands out, and waits for it.
struct Sink {
  std::mutex m;
  std::condition_variable cv;
  std::vector<ViewFrame> frames;
  void operator()(ViewFrame f) {
    std::lock_guard<std::mutex> l(m);
    frames.push_back(std::move(f));
    cv.notify_all();
  }
  // The next frame after `count` (a JSON meta), or fails the test after 30 s.
  nlohmann::json waitFor(size_t count, std::string* jpeg = nullptr) {
    std::unique_lock<std::mutex> l(m);
    bool ok = cv.wait_for(l, std::chrono::seconds(30), [&] { return frames.size() > count; });
    if (!ok) {
      ADD_FAILURE() << "no frame within 30 s";
      return nlohmann::json{};
    }
    if (jpeg) *jpeg = frames[count].jpeg;
    return nlohmann::json::parse(frames[count].meta);
  }
};

// A started session on a 24x16 ball scene written into dir, with a small grid; one thread.
inline std::unique_ptr<ViewSession> makeSession(const std::string& dir, Sink& sink, ViewOptions vo = {},
                                                int maxSpp = 16) {
  std::string xml = dir + "/ball.xml";
  writeBallScene(xml, 24, 16, "");
  auto scene = std::make_unique<Scene>();
  loadScene(xml, {}, *scene);
  useSmallGrid(scene->integrator.grid);
  vo.threads = 1;
  vo.maxSpp = maxSpp;
  auto s = std::make_unique<ViewSession>(std::move(scene), xml, vo);
  s->start([&sink](ViewFrame f) { sink(std::move(f)); });
  return s;
}

// Asks for frames until one satisfies pred; null after `tries` frames without one. Other
// messages the session hands out (status, error, hello) are passed over: pred sees frames only.
template <class Pred>
nlohmann::json frameWhere(ViewSession& session, Sink& sink, Pred pred, int tries = 400) {
  for (int i = 0; i < tries; ++i) {
    size_t n;
    {
      std::lock_guard<std::mutex> l(sink.m);
      n = sink.frames.size();
    }
    session.requestFrame();
    nlohmann::json f = sink.waitFor(n);
    if (f.is_null()) return f;
    if (f.value("type", "") == "frame" && pred(f)) return f;
  }
  ADD_FAILURE() << "no such frame in " << tries;
  return nlohmann::json{};
}

inline double meanOfImage(const Image& img) {
  double s = 0.0;
  for (float v : img.rgb) s += v;
  return s / double(std::max<size_t>(1, img.rgb.size()));
}

}  // namespace envgi::test
