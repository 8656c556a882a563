// `envgi view SCENE.xml`: the scene in a browser, rendered progressively and steered from the
// page; local (127.0.0.1) by default, or on a headless server behind an SSH tunnel.
#include <spdlog/spdlog.h>

#include <random>

#include "cli/Commands.h"
#include "gpu/CudaExecutor.h"
#include "scene/NameTables.h"
#include "scene/SceneLoader.h"
#include "view/ViewServer.h"

namespace envgi::cli {

namespace {
struct ViewArgs {
  std::string scene, host = "127.0.0.1", integrator, strategy, device = "auto";
  int port = 8000, threads = 0, maxSpp = 4096, gpu = 0, minSpp = 16;
  float noiseThreshold = 0.f;
  std::vector<std::string> defines;
};

std::string makeToken() {
  std::random_device rd;
  const char* hex = "0123456789abcdef";
  std::string t;
  for (int i = 0; i < 32; ++i) t += hex[rd() % 16];
  return t;
}

std::unique_ptr<Scene> loadViewedScene(const ViewArgs& a) {
  auto scene = std::make_unique<Scene>();
  loadScene(a.scene, parseDefines(a.defines), *scene);
  if (!a.integrator.empty()) scene->integrator.type = findIntegrator(a.integrator);
  if (!a.strategy.empty()) scene->integrator.setStrategy(a.strategy);
  return scene;
}

void runView(const ViewArgs& a) {
  auto scene = loadViewedScene(a);
  ViewOptions vo;
  vo.reload = [a] { return loadViewedScene(a); };
  vo.threads = a.threads;
  vo.maxSpp = a.maxSpp;
  vo.noiseThreshold = a.noiseThreshold;
  vo.adaptiveMinSpp = a.minSpp;
  if (gpu::chooseCuda(a.device, "--device", scene.get())) {
    vo.prepare = gpu::cudaPreparer(a.gpu);
    spdlog::info("view: rendering on {}", gpu::deviceName(a.gpu));
  }
  ViewSession session(std::move(scene), a.scene, vo);
  ViewServerOptions so;
  so.host = a.host;
  so.port = a.port;
  if (a.host != "127.0.0.1" && a.host != "::1" && a.host != "localhost") so.token = makeToken();
  if (so.host == "localhost") so.host = "127.0.0.1";
  ViewServer server(session, so);
  std::string url = fmt::format("http://{}:{}/", so.host == "0.0.0.0" ? "HOST" : so.host, server.port());
  if (!so.token.empty()) url += "?token=" + so.token;
  // Printed even with -q: without the URL (and its token) the viewer cannot be opened.
  if (spdlog::should_log(spdlog::level::info))
    spdlog::info("view: open {}  (Ctrl-C stops)", url);
  else
    fmt::print("view: open {}  (Ctrl-C stops)\n", url);
  std::fflush(stdout);
  server.run();
  spdlog::info("view: stopped after {} frames", session.framesSent());
}
}  // namespace

void addViewCommand(CLI::App& app) {
  auto a = std::make_shared<ViewArgs>();
  CLI::App* c = app.add_subcommand("view", "Render a scene progressively in the browser, steered from the page");
  c->add_option("scene", a->scene, "Scene file (.xml)")->required()->check(CLI::ExistingFile);
  c->add_option("--port", a->port, "Port to listen on (0: any free one)")->check(CLI::Range(0, 65535));
  c->add_option("--host", a->host, "Address to bind (default 127.0.0.1; anything wider requires the printed token)");
  c->add_option("--integrator", a->integrator, "Integrator: " + nameList(kIntegratorNames));
  c->add_option("--strategy", a->strategy, "Environment strategy: " + strategyNameList());
  addThreadsOption(c, &a->threads);
  c->add_option("--max-spp", a->maxSpp, "Stop refining at this many samples per pixel")->check(atLeast(1));
  c->add_option("--noise-threshold", a->noiseThreshold,
                "Adaptive sampling, as in render: a pixel stops refining once it and its neighbours are below this "
                "noise (0: off; the page can change it)")
      ->check(CLI::Range(0.0, 10.0))
      ->check(finiteNumber());
  c->add_option("--min-spp", a->minSpp, "Adaptive sampling: samples every pixel takes before it may stop (default 16)")
      ->check(atLeast(2));
  c->add_option("-D", a->defines, "Set a scene parameter: -D name=value (repeatable)");
  c->add_option("--device", a->device, "cpu | cuda | auto (default: auto, CUDA where a GPU is present)");
  c->add_option("--gpu", a->gpu, "Which CUDA device (default 0)")->check(atLeast(0));
  c->callback([a] { runView(*a); });
}

}  // namespace envgi::cli
