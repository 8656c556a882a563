// path or direct over any tracer, as every executor runs them: whole per sample (renderPixel),
// a bounce a call (path regeneration on the GPU), or with the trace taken out of the bounce
// (the wave stages, wavefront/WaveStages.h). The integrators themselves are the shared
// templates of integrators/.
#pragma once

#include "integrators/DirectIntegrator.h"
#include "integrators/PathIntegrator.h"

namespace envgi {

enum class SampleIntegratorType : int { Path = 0, Direct = 1 };

// direct with at most one light sample and one BSDF sample (the paper's figures' settings,
// the study's strategies) is a path of at most two segments without roulette: the same draws
// in the same order and the same MIS weights (Eq. 6 with nE, nB in {0, 1}; weight 1 where one
// count is 0), so an executor may shade it a bounce at a time as that path.
ENVGI_HD inline bool directIsOneBouncePath(const DirectParams& dp) {
  // The whole collapsed map at each point is not a path's one light sample.
  // The path's weights are the power heuristic's.
  return dp.envStrategy != EnvStrategy::PointsAll && dp.heuristic == MisHeuristic::Power && dp.emitterSamples >= 0 &&
         dp.emitterSamples <= 1 && dp.bsdfSamples >= 0 && dp.bsdfSamples <= 1 &&
         dp.emitterSamples + dp.bsdfSamples > 0;
}
ENVGI_HD inline PathParams directAsPath(const DirectParams& dp) {
  PathParams p;
  p.maxDepth = 2;
  p.rrDepth = 2;  // roulette from depth 2 on, where the path has already ended
  p.hideEmitters = dp.hideEmitters;
  p.envStrategy = dp.envStrategy;
  p.lightSample = dp.emitterSamples > 0;
  p.bsdfSample = dp.bsdfSamples > 0;
  return p;
}

template <class Tracer>
struct SampleIntegrator {
  SampleIntegratorType type = SampleIntegratorType::Path;
  PathParams path;
  DirectParams direct;
  const SceneView* scene = nullptr;
  Tracer tracer;

  ENVGI_HD Color operator()(const Ray& ray, Sampler& smp, uint64_t* rays) const {
    return type == SampleIntegratorType::Direct ? directTrace(*scene, tracer, ray, smp, direct, rays)
                                                : pathTrace(*scene, tracer, ray, smp, path, rays);
  }
  // The same sample one bounce a call (regeneratePaths): begin, then step until it returns
  // false; the radiance is then in the state's L. direct is one step.
  ENVGI_HD PathState begin(const Ray& ray) const { return pathBegin(ray); }
  ENVGI_HD bool step(PathState* st, Sampler& smp, uint64_t* rays) const {
    if (type == SampleIntegratorType::Direct) {
      st->L = directTrace(*scene, tracer, st->ray, smp, direct, rays);
      return false;
    }
    return pathStep(*scene, tracer, st, smp, path, rays);
  }
  // step() with the trace taken out, for an executor that traces many paths' rays together
  // (the wave stages): path, and direct where it is a one-bounce path (directAsPath);
  // direct with more samples traces several rays inside its one step.
  ENVGI_HD bool shadesAfterTrace() const {
    return type == SampleIntegratorType::Path || directIsOneBouncePath(direct);
  }
  // The path that shade() follows: path's own, or direct's as a one-bounce path.
  ENVGI_HD PathParams shadedPath() const { return type == SampleIntegratorType::Path ? path : directAsPath(direct); }
  // parts: where the bounce's parts come from (integrators/BounceParts.h).
  template <class Shadow, class Parts>
  ENVGI_HD bool shade(PathState* st, bool found, const Hit& h, Sampler& smp, const Shadow& shadow,
                      const Parts& parts) const {
    return pathShade(*scene, st, found, h, smp, shadedPath(), shadow, parts);
  }
};

// Integrators that run one bounce a call, so path regeneration and the wave stages can
// drive them.
template <class T>
struct RunsByBounce {
  static constexpr bool value = false;
};
template <class Tracer>
struct RunsByBounce<SampleIntegrator<Tracer>> {
  static constexpr bool value = true;
};

}  // namespace envgi
