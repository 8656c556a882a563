// libFuzzer target: the viewer's messages (ViewSession::handle), one JSON message a line, sent
// to a session that renders on its own thread meanwhile, as a page would send them; each input
// waits for the worker to take its changes. A message may be refused with std::runtime_error;
// anything else, a crash or a sanitizer report on either thread, is a defect.
#include <cstdlib>
#include <fstream>
#include <memory>
#include <stdexcept>
#include <string>

#include "fuzz/FuzzInput.h"
#include "scene/SceneLoader.h"
#include "view/ViewSession.h"

namespace {

envgi::ViewSession& session() {
  static std::unique_ptr<envgi::ViewSession> s = [] {
    std::string xml = (envgi::fuzz::inputDir() / "ball.xml").string();
    std::ofstream(xml) << R"(<scene version="3.0.0">
  <integrator type="path"><integer name="max_depth" value="3"/></integrator>
  <sensor type="perspective"><float name="fov" value="40"/>
    <transform name="to_world"><lookat origin="0, 1, 4" target="0, 0, 0" up="0, 1, 0"/></transform>
    <film type="hdrfilm"><integer name="width" value="16"/><integer name="height" value="12"/></film></sensor>
  <emitter type="constant"><rgb name="radiance" value="1"/></emitter>
  <shape type="sphere"><bsdf type="dielectric"/></shape>
  <shape type="rectangle"><transform name="to_world"><rotate x="1" angle="-90"/><scale value="3"/><translate y="-1"/></transform></shape>
</scene>)";
    auto scene = std::make_unique<envgi::Scene>();
    envgi::loadScene(xml, {}, *scene);
    // Every integrator a message may pick gets maps this size: the defaults (250,000 photons
    // each) took 13 s under the sanitizers, 30 s on a loaded machine, for no more coverage.
    scene->integrator.photon.globalPhotons = 2000;
    scene->integrator.photon.causticPhotons = 2000;
    scene->integrator.sppm.photonCount = 2000;
    scene->integrator.grid.globalPhotons = 2000;
    scene->integrator.grid.causticPhotons = 0;
    scene->integrator.grid.resolution = 4;
    scene->integrator.grid.gatherRays = 4;
    envgi::ViewOptions vo;
    vo.threads = 1;
    vo.maxSpp = 4;
    auto v = std::make_unique<envgi::ViewSession>(std::move(scene), xml, vo);
    v->start([](envgi::ViewFrame) {});
    return v;
  }();
  return *s;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  std::string text(reinterpret_cast<const char*>(data), size);
  size_t start = 0;
  for (int n = 0; n < 16 && start <= text.size(); ++n) {
    size_t end = text.find('\n', start);
    if (end == std::string::npos) end = text.size();
    try {
      session().handle(text.substr(start, end - start));
    } catch (const std::runtime_error&) {
    }
    start = end + 1;
  }
  // The worker builds the camera and the executor from what was taken: let it, so that a
  // message that kills the worker fails on the input that sent it.
  if (!session().waitForWorker(30.0) || session().renderFailures() > 0) std::abort();
  return 0;
}
