// `envgi photons SCENE.xml -o photons.png`: the paper's Figure 4(a), the stored photons drawn
// over a dimmed direct-light render (global photons orange, caustic photons cyan).
#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include <filesystem>
#include <memory>

#include "accel/EmbreeAccel.h"
#include "cli/Commands.h"
#include "core/Files.h"
#include "render/PhotonShooter.h"
#include "render/Renderer.h"
#include "scene/SceneLoader.h"

namespace envgi::cli {

namespace {

struct PhotonsArgs {
  std::string scene, output;
  std::vector<std::string> defines;
  size_t global = 20000, caustic = 20000;
};

void runPhotons(const PhotonsArgs& a) {
  std::map<std::string, std::string> defs = parseDefines(a.defines);
  const std::string ext = requireOutputExtension(a.output, {".png", ".exr"}, "output");  // before the photons are shot
  Scene scene;
  loadScene(a.scene, defs, scene);
  scene.integrator = IntegratorSettings{};
  scene.integrator.type = IntegratorType::Direct;
  scene.finalize();
  EmbreeAccel accel(scene);
  PhotonShootSettings ps;
  ps.globalPhotons = a.global;
  ps.causticPhotons = a.caustic;
  ps.seed = scene.sampler.seed;
  PhotonMap global, caustic;
  PhotonShootStats st;
  shootPhotons(scene, accel, ps, &global, &caustic, &st);
  spdlog::info("{} global photons ({} emitted), {} caustic photons ({} emitted), {:.2f} s", st.storedGlobal,
               st.emittedGlobal, st.storedCaustic, st.emittedCaustic, st.traceSeconds + st.buildSeconds);

  RenderOptions ro;
  ro.spp = 4;
  ro.progress = false;
  Image img = render(scene, accel, ro, nullptr);
  for (float& v : img.rgb) v *= 0.25f;  // dim, so the dots stand out
  const Camera& cam = scene.view().camera;
  Vec3f eye = cam.toWorld.point(Vec3f(0.f));
  size_t drawn = 0;
  auto draw = [&](const PhotonMap& m, Color c) {
    for (const Photon& ph : m.photons()) {
      float x, y;
      if (!projectToFilm(cam, ph.p, &x, &y)) continue;
      Vec3f d = ph.p - eye;
      float dist = length(d);
      Hit h;
      // Drawn only where the camera sees the surface the photon landed on.
      if (accel.intersect(Ray{eye, d / dist, INFINITY}, &h) && h.t < dist * (1.f - 1e-3f)) continue;
      img.set(int(x), int(y), c);
      ++drawn;
    }
  };
  draw(global, Color(1.f, 0.55f, 0.15f));
  draw(caustic, Color(0.2f, 0.85f, 1.f));
  saveImage(img, a.output);
  spdlog::info("wrote {} with {} visible photons: global photons orange, caustic photons cyan, over a dimmed "
               "direct-light render",
               std::filesystem::absolute(a.output).string(), drawn);
}

}  // namespace

void addPhotonsCommand(CLI::App& app) {
  auto a = std::make_shared<PhotonsArgs>();
  CLI::App* c = app.add_subcommand("photons", "Draw the photon maps over the scene (the paper's Figure 4a)");
  c->add_option("scene", a->scene, "Scene file (.xml)")->required()->check(CLI::ExistingFile);
  c->add_option("-o,--output", a->output, "Image (.png or .exr)")->required();
  c->add_option("--global", a->global, "Global photons to store")->check(atLeast(0));
  c->add_option("--caustic", a->caustic, "Caustic photons to store")->check(atLeast(0));
  c->add_option("-D", a->defines, "Set a scene parameter: -D name=value (repeatable)");
  c->callback([a] { runPhotons(*a); });
}

}  // namespace envgi::cli
