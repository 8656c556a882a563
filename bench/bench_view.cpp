// The viewer's budgets on this machine: the time from a camera move to the first frame from
// the new camera (render 1 spp, tone map, JPEG), as the page sees it while orbiting, on the
// bundled scenes at 256^2 with path and with grid; the budget is 50 ms on 2 cores.
// Run: build/bin/envgi_bench_view --benchmark_repetitions=3 --benchmark_report_aggregates_only=true
#include <benchmark/benchmark.h>

#include <cmath>
#include <condition_variable>
#include <mutex>
#include <nlohmann/json.hpp>

#include "scene/SceneLoader.h"
#include "view/ViewSession.h"

using namespace envgi;
using json = nlohmann::json;

namespace {
struct Frames {
  std::mutex m;
  std::condition_variable cv;
  int lastVersion = -1;
  std::string lastIntegrator;
  size_t bytes = 0;
};
}  // namespace

static void BM_OrbitMoveToFrame(benchmark::State& state, const char* sceneName, const char* integrator) {
  auto scene = std::make_unique<Scene>();
  std::string path = std::string(ENVGI_SOURCE_DIR) + "/scenes/" + sceneName + ".xml";
  loadScene(path, {{"res", "256"}}, *scene);
  ViewOptions vo;
  vo.maxSpp = 1;  // the orbiting case: one sample a pixel per camera
  ViewSession session(std::move(scene), path, vo);
  Frames fr;
  session.start([&fr](ViewFrame f) {
    json m = json::parse(f.meta);
    if (m["type"] != "frame") return;
    std::lock_guard<std::mutex> l(fr.m);
    fr.lastVersion = m["cameraVersion"];
    fr.lastIntegrator = m["integrator"];
    fr.bytes = f.jpeg.size();
    fr.cv.notify_all();
  });
  json hello = json::parse(session.hello());
  session.handle(json{{"type", "integrator"}, {"value", integrator}}.dump());
  std::vector<float> o = hello["camera"]["origin"], t = hello["camera"]["target"], up = hello["camera"]["up"];
  float dx = o[0] - t[0], dz = o[2] - t[2];
  int version = 0;
  auto moveAndWait = [&] {
    ++version;
    float a = 0.02f * float(version), c = std::cos(a), s = std::sin(a);
    json cam = {{"type", "camera"},
                {"origin", {t[0] + c * dx - s * dz, o[1], t[2] + s * dx + c * dz}},
                {"target", t},
                {"up", up},
                {"version", version}};
    session.handle(cam.dump());
    // As the page does: ask for the next frame after each one, until one shows this camera.
    std::unique_lock<std::mutex> l(fr.m);
    while (!(fr.lastVersion == version && fr.lastIntegrator == integrator)) {
      l.unlock();
      session.requestFrame();
      l.lock();
      fr.cv.wait_for(l, std::chrono::milliseconds(2));
    }
  };
  moveAndWait();  // the integrator's preparation (grid: photons and the grid) is not timed
  for (auto _ : state) moveAndWait();
  state.counters["jpeg_kB"] = double(fr.bytes) / 1e3;
  session.stop();
}
BENCHMARK_CAPTURE(BM_OrbitMoveToFrame, buddha_path, "buddha", "path")->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK_CAPTURE(BM_OrbitMoveToFrame, cornell_path, "cornell-box", "path")->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK_CAPTURE(BM_OrbitMoveToFrame, teapot_path, "teapot-glass", "path")->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK_CAPTURE(BM_OrbitMoveToFrame, buddha_grid, "buddha", "grid")->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK_CAPTURE(BM_OrbitMoveToFrame, cornell_grid, "cornell-box", "grid")->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK_CAPTURE(BM_OrbitMoveToFrame, buddha_direct, "buddha", "direct")->Unit(benchmark::kMillisecond)->UseRealTime();

BENCHMARK_MAIN();
