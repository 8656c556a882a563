// SPPM's driver (Hachisuka and Jensen 2009): each pass of the render loop is one SPPM
// iteration, camera pass (visible points) then photon pass (hashed grid, atomics) and the
// progressive radius update, run with oneTBB over the per-path code of integrators/Sppm.h.
#pragma once

#include <vector>

#include "accel/EmbreeAccel.h"
#include "integrators/Sppm.h"
#include "render/PhotonShooter.h"
#include "render/PassExecutor.h"

#include <tbb/task_arena.h>

namespace envgi {

struct SppmStats {
  int passesDone = 0;
  uint64_t photonsShot = 0, photonHits = 0, rays = 0;
  double cameraSeconds = 0.0, photonSeconds = 0.0;
  size_t bytes = 0;
  float meanRadius = 0.f;
};

class SppmExecutor final : public PassExecutor {
 public:
  SppmExecutor(const Scene& scene, const EmbreeAccel& accel, const SppmParams& params, int threads);
  std::string deviceName() const override { return "cpu"; }
  // One SPPM iteration a pass, so checkpoints and Ctrl-C come between iterations.
  int maxPassSize() const override { return 1; }
  void runPass(int s0, int s1, Progress& progress, PassCounters* counters) override;
  // The estimate so far times the iterations done, so the loop's mean is the estimate.
  void readFilm(FilmSums* out) override;
  SppmStats stats() const;

 private:
  void iteration(int pass, PassCounters* counters);

  const Scene& scene_;
  EmbreeTracer tracer_;
  SppmParams p_;
  tbb::task_arena arena_;
  PhotonEmitter emitter_;
  bool anyLight_;
  int W_, H_;
  std::vector<float> r2_, n_, phi_;
  std::vector<Color> tau_, ld_;
  std::vector<uint32_t> m_;
  std::vector<VisiblePoint> vps_;
  std::vector<Vec3f> vpPos_;
  std::vector<char> vpValid_;
  HashGrid grid_;
  SppmStats st_;
};

}  // namespace envgi
