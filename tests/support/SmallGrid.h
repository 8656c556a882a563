// The grid integrator's settings cut down for a test: few photons and points, few gather rays,
// so that the grid is made in milliseconds.
#pragma once

#include "scene/IntegratorSettings.h"

namespace envgi::test {

inline void useSmallGrid(GridSettings& grid) {
  grid.globalPhotons = 5000;
  grid.causticPhotons = 0;
  grid.resolution = 8;
  grid.gatherRays = 16;
}

}  // namespace envgi::test
