// The example scenes under scenes/, read by the unit tests (envgi_tests defines
// ENVGI_SOURCE_DIR).
#pragma once

#include <string>

#include "scene/SceneLoader.h"

namespace envgi::test {

// A bundled scene (scenes/NAME.xml) at res x res pixels with the given integrator, not yet
// finalized.
inline void loadBundledSmall(const std::string& name, int res, IntegratorType type, Scene* s) {
  loadScene(std::string(ENVGI_SOURCE_DIR) + "/scenes/" + name + ".xml", {{"res", std::to_string(res)}}, *s);
  s->camera.width = s->camera.height = res;
  s->integrator.type = type;
}

}  // namespace envgi::test
