#include "render/PhotonShooter.h"

#include <spdlog/spdlog.h>
#include <tbb/parallel_for.h>

#include <chrono>

namespace envgi {

PhotonEmitter makePhotonEmitter(const Scene& scene) {
  const SceneView& sc = scene.view();
  PhotonEmitter e;
  e.center = (sc.boundsMin + sc.boundsMax) * 0.5f;
  e.radius = fmaxf(1e-3f, 0.5f * length(sc.boundsMax - sc.boundsMin) * 1.001f);
  double envPower = scene.env ? double(kPi) * e.radius * e.radius * scene.env->luminancePower() : 0.0;
  double areaPower = 0.0;
  for (int i = 0; i < sc.lightCount; ++i) areaPower += kPi * sc.lights[i].area * luminance(sc.lights[i].radiance);
  e.envProb = envPower + areaPower > 0.0 ? float(envPower / (envPower + areaPower)) : 0.f;
  return e;
}

void shootPhotons(const Scene& scene, const EmbreeAccel& accel, const PhotonShootSettings& s, PhotonMap* global,
                  PhotonMap* caustic, PhotonShootStats* stats) {
  using Clock = std::chrono::steady_clock;
  auto t0 = Clock::now();
  const SceneView& sc = scene.view();
  PhotonEmitter emitter = makePhotonEmitter(scene);
  bool anyLight = emitter.emitsLight(sc);
  std::vector<Photon> g, c;
  bool gDone = s.globalPhotons == 0, cDone = s.causticPhotons == 0;
  uint64_t emitted = 0, gEmitted = 0, cEmitted = 0;
  // A scene without caustic paths never fills its caustic map: stop after a generous bound.
  const uint64_t cap = 64 * std::max(s.globalPhotons, s.causticPhotons) + 100000;
  const int batch = 1 << 15, chunk = 1024;
  EmbreeTracer tracer{&accel};
  double lastLog = 0.0;
  if (!anyLight) {
    spdlog::warn("the scene emits no light: no photons shot");
    gDone = cDone = true;
  }
  while (!(gDone && cDone) && emitted < cap) {
    int chunks = batch / chunk;
    std::vector<std::vector<Photon>> gLocal(static_cast<size_t>(chunks)), cLocal(static_cast<size_t>(chunks));
    tbb::parallel_for(0, chunks, [&](int ci) {
      Sampler smp;
      smp.type = SamplerType::Independent;
      smp.seed = s.seed ^ kPhotonMapStream;
      for (int j = 0; j < chunk; ++j) {
        uint64_t id = emitted + uint64_t(ci) * chunk + j;
        smp.start(id, 0);
        Ray ray;
        Color power;
        if (!emitter.emit(sc, smp, &ray, &power)) continue;
        tracePhoton(sc, tracer, ray, power, smp, s.maxDepth,
                    [&](const SurfaceInteraction& si, Vec3f wi, Color pw, bool isCaustic, int) {
                      if (isCaustic) {
                        if (!cDone) cLocal[size_t(ci)].push_back({si.p, wi, faceForward(si.ng, wi), pw});
                      } else if (!gDone) {
                        gLocal[size_t(ci)].push_back({si.p, wi, faceForward(si.ng, wi), pw});
                      }
                    });
      }
    });
    emitted += uint64_t(batch);
    // Chunks are appended in order, so the maps do not depend on the thread count.
    for (int ci = 0; ci < chunks; ++ci) {
      g.insert(g.end(), gLocal[size_t(ci)].begin(), gLocal[size_t(ci)].end());
      c.insert(c.end(), cLocal[size_t(ci)].begin(), cLocal[size_t(ci)].end());
    }
    if (!gDone) gEmitted = emitted;
    if (!cDone) cEmitted = emitted;
    gDone = gDone || g.size() >= s.globalPhotons;
    cDone = cDone || c.size() >= s.causticPhotons;
    // No specular surface in reach of the lights: do not spin on an empty caustic map.
    if (!cDone && c.empty() && emitted >= (uint64_t(1) << 20)) {
      spdlog::info("no caustic paths after {} photons: the caustic map stays empty", emitted);
      cDone = true;
    }
    double t = std::chrono::duration<double>(Clock::now() - t0).count();
    if (s.progress && t - lastLog >= 2.0) {
      lastLog = t;
      spdlog::info("photon pass: {} emitted, {}/{} global, {}/{} caustic stored, {:.1f} s", emitted, g.size(),
                   s.globalPhotons, c.size(), s.causticPhotons, t);
    }
  }
  for (Photon& p : g) p.power = p.power / float(std::max<uint64_t>(gEmitted, 1));
  for (Photon& p : c) p.power = p.power / float(std::max<uint64_t>(cEmitted, 1));
  auto t1 = Clock::now();
  if (stats) {
    stats->emittedGlobal = gEmitted;
    stats->emittedCaustic = cEmitted;
    stats->storedGlobal = g.size();
    stats->storedCaustic = c.size();
  }
  global->build(std::move(g));
  caustic->build(std::move(c));
  if (s.irradianceStride > 0) {
    auto precompute = [&](PhotonMap* map, float radius) {
      size_t n = map->beginIrradiance(s.irradianceStride);
      tbb::parallel_for(size_t(0), n, [&](size_t i) { map->estimateIrradiance(i, s.irradianceLookup, radius); });
      map->endIrradiance();
    };
    precompute(global, s.irradianceRadius);
    precompute(caustic, s.causticIrradianceRadius);
  }
  if (stats) {
    stats->traceSeconds = std::chrono::duration<double>(t1 - t0).count();
    stats->buildSeconds = std::chrono::duration<double>(Clock::now() - t1).count();
    stats->bytes = global->bytes() + caustic->bytes();
  }
}

}  // namespace envgi
