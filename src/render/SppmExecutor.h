// SPPM's CPU driver (Hachisuka and Jensen 2009): each pass of the render loop is one SPPM
// iteration, camera step (visible points), hashed grid, photon step (atomics) and the
// progressive radius update, run with oneTBB over the per-element steps of integrators/Sppm.h.
// The tracer is Embree, or the BVH the GPU traverses (to check the GPU's bodies on the CPU).
#pragma once

#include <vector>

#include <tbb/task_arena.h>

#include "accel/EmbreeAccel.h"
#include "integrators/Sppm.h"
#include "render/PhotonShooter.h"
#include "render/SppmPassExecutor.h"
#include "scene/Scene.h"

namespace envgi {

template <class Tracer>
class SppmExecutor final : public SppmPassExecutor {
 public:
  SppmExecutor(const Scene& scene, Tracer tracer, const SppmParams& params, int threads);
  std::string deviceName() const override { return "cpu"; }
  void runPass(int s0, int s1, Progress& progress, PassCounters* counters) override;
  // The estimate so far times the iterations done, so the loop's mean is the estimate.
  void readFilm(FilmSums* out) override;
  SppmStats stats() const override;

 private:
  void iteration(int pass, PassCounters* counters);

  const Scene& scene_;
  Tracer tracer_;
  SppmParams p_;
  tbb::task_arena arena_;
  PhotonEmitter emitter_;
  bool anyLight_;
  int W_, H_;
  std::vector<float> r2_, n_, phi_;
  std::vector<Color> tau_, ld_;
  std::vector<float> weightSum_;  // empty unless the filter has negative lobes
  std::vector<uint32_t> m_;
  std::vector<VisiblePoint> vps_;
  std::vector<Vec3f> vpPos_;
  std::vector<char> vpValid_;
  HashGrid grid_;
  SppmStats st_;
};

}  // namespace envgi
