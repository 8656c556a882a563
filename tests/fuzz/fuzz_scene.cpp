// libFuzzer target: scene XML (loadScene), with the defaults a render would use. Shapes
// and maps named by file resolve next to the input, where there are none: what is reached
// is the XML, its properties and the analytic shapes.
#include <stdexcept>

#include "fuzz/FuzzInput.h"
#include "scene/SceneLoader.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  std::string path = envgi::fuzz::writeInput(data, size, ".xml");
  try {
    envgi::Scene scene;
    envgi::loadScene(path, {}, scene);
  } catch (const std::runtime_error&) {
  }
  return 0;
}
