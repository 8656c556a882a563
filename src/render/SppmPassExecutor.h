// What the render loop and the log see of an SPPM driver, on either device: one SPPM iteration
// a pass (so checkpoints and Ctrl-C come between iterations), and its statistics.
#pragma once

#include <cstddef>
#include <cstdint>

#include "integrators/Sppm.h"
#include "render/PassExecutor.h"

namespace envgi {

struct SppmStats {
  int passesDone = 0;
  uint64_t photonsShot = 0, photonHits = 0, rays = 0;
  double cameraSeconds = 0.0, photonSeconds = 0.0;
  size_t bytes = 0;
  float meanRadius = 0.f;
};

// Checks the options every SPPM driver takes; throws with the option's name.
void checkSppmParams(const SppmParams& p);

class SppmPassExecutor : public PassExecutor {
 public:
  int maxPassSize() const override { return 1; }
  virtual SppmStats stats() const = 0;
};

}  // namespace envgi
