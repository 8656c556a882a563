// Equal time per frame: what path and the grid's two bases (SH, and the paper's directions)
// show after 1, 16 and 100 ms of camera passes, once each has what comes before them (photon
// maps, the grid). A frame is 1-spp passes until its budget is spent, the first pass always
// whole: what the viewer shows for that frame budget. Error: RMSE against path at 1024 spp.
// Prints a markdown table (docs/grid.md). Usage: envgi_grid_frames [RES] [SCENE...]
#include <chrono>
#include <cstdio>
#include <string>
#include <vector>

#include "render/Progress.h"
#include "render/Renderer.h"
#include "scene/SceneLoader.h"
#include "study/ErrorMetrics.h"

using namespace envgi;
using Clock = std::chrono::steady_clock;

namespace {

double secondsSince(Clock::time_point t0) { return std::chrono::duration<double>(Clock::now() - t0).count(); }

struct Method {
  const char* name;
  IntegratorType type;
  const char* basis;
};

}  // namespace

int main(int argc, char** argv) {
  const std::string res = argc > 1 ? argv[1] : "128";
  std::vector<std::string> scenes;
  for (int i = 2; i < argc; ++i) scenes.push_back(argv[i]);
  if (scenes.empty()) scenes = {"cornell-box", "buddha", "teapot-glass"};
  const Method methods[] = {{"path", IntegratorType::Path, "sh"},
                            {"grid, sh", IntegratorType::Grid, "sh"},
                            {"grid, directions", IntegratorType::Grid, "directions"}};
  std::printf("| scene | method | before the passes (s) | frame budget (ms) | spp | frame (ms) | RMSE |\n");
  std::printf("| --- | --- | --- | --- | --- | --- | --- |\n");
  for (const std::string& name : scenes) {
    Scene scene;
    loadScene(std::string(ENVGI_SOURCE_DIR) + "/scenes/" + name + ".xml", {{"res", res}}, scene);
    scene.integrator.setStrategy("mis");
    scene.finalize();
    EmbreeAccel accel(scene);
    RenderOptions o;
    o.progress = false;
    scene.integrator.type = IntegratorType::Path;
    o.spp = 1024;
    const Image ref = render(scene, accel, o, nullptr);
    const Camera cam = scene.view().camera;
    for (const Method& m : methods) {
      scene.integrator.type = m.type;
      scene.integrator.grid.basis = m.basis;
      scene.finalize();
      o.spp = 4096;
      const Clock::time_point t0 = Clock::now();
      PreparedRender pr = prepareRender(scene, accel, o);
      const double before = secondsSince(t0);
      for (double budgetMs : {1.0, 16.0, 100.0}) {
        pr.executor->restart(cam);
        Progress progress(0, false);
        const Clock::time_point f0 = Clock::now();
        int spp = 0;
        do {
          PassCounters counters;
          pr.executor->runPass(spp, spp + 1, progress, &counters);
          ++spp;
        } while (secondsSince(f0) * 1e3 < budgetMs);
        const double frameMs = secondsSince(f0) * 1e3;
        FilmSums film;
        pr.executor->readFilm(&film);
        const ImageError e = imageError(filmMean(film, cam.width, cam.height, spp), ref);
        std::printf("| %s | %s | %.2f | %.0f | %d | %.1f | %.5f |\n", name.c_str(), m.name, before, budgetMs, spp,
                    frameMs, e.rmse);
        std::fflush(stdout);
      }
    }
  }
  return 0;
}
