#include "render/PhotonShooter.h"

#include <spdlog/spdlog.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_invoke.h>

#include <chrono>
#include <stdexcept>

namespace envgi {

PhotonEmitter makePhotonEmitter(const Scene& scene) {
  const SceneView& sc = scene.view();
  PhotonEmitter e;
  e.center = (sc.boundsMin + sc.boundsMax) * 0.5f;
  e.radius = fmaxf(1e-3f, 0.5f * length(sc.boundsMax - sc.boundsMin) * 1.001f);
  double envPower = scene.env ? double(kPi) * e.radius * e.radius * scene.env->luminancePower() : 0.0;
  double areaPower = 0.0;
  for (int i = 0; i < sc.lightCount; ++i) areaPower += kPi * sc.lights[i].area * luminance(sc.lights[i].radiance);
  // A delta light's power: a sun's irradiance over the bounding sphere's cross-section, a point
  // light's intensity over the whole sphere of directions, a spot's over its cone (the falloff
  // taken as full: a bound, which only shifts how photons are shared among the lights).
  double deltaPower = 0.0;
  for (int i = 0; i < sc.deltaLightCount; ++i) {
    const DeltaLight& l = sc.deltaLights[i];
    double solidAngle = isSpot(l) ? 2.0 * kPi * (1.0 - l.cosCutoff) : 4.0 * kPi;
    deltaPower += luminance(l.value) * (l.point ? solidAngle : double(kPi) * e.radius * e.radius);
  }
  double total = envPower + areaPower + deltaPower;
  e.envProb = total > 0.0 ? float(envPower / total) : 0.f;
  e.deltaProb = total > 0.0 ? float(deltaPower / total) : 0.f;
  return e;
}

namespace {

template <class Tracer>
class CpuPhotonTracer final : public PhotonBatchTracer {
 public:
  CpuPhotonTracer(const Scene& scene, Tracer tracer, std::string name)
      : scene_(scene), tracer_(tracer), emitter_(makePhotonEmitter(scene)), name_(std::move(name)) {}
  std::string deviceName() const override { return name_; }
  void trace(const PhotonTraceRequest& r, std::vector<PhotonBatch>* out) override {
    const int chunk = 1024, chunks = kPhotonSubBatch / chunk;
    std::vector<PhotonBatch> local(static_cast<size_t>(chunks));
    const SceneView& sc = scene_.view();
    tbb::parallel_for(0, chunks, [&](int ci) {
      PhotonBatch& b = local[size_t(ci)];
      for (int j = 0; j < chunk; ++j)
        shootPhoton(sc, tracer_, emitter_, r.seed ^ kPhotonMapStream, r.first + uint64_t(ci) * chunk + j, 0,
                    r.maxDepth, [&](const SurfaceInteraction& si, Vec3f wi, Color pw, bool isCaustic, int) {
                      if (isCaustic ? r.caustic : r.global)
                        (isCaustic ? b.caustic : b.global).push_back(makePhoton(si, wi, pw));
                    });
    });
    // Chunks are appended in order, so the maps do not depend on the thread count.
    PhotonBatch all;
    for (PhotonBatch& b : local) {
      all.global.insert(all.global.end(), b.global.begin(), b.global.end());
      all.caustic.insert(all.caustic.end(), b.caustic.begin(), b.caustic.end());
    }
    out->assign(1, std::move(all));
  }

 private:
  const Scene& scene_;
  Tracer tracer_;
  PhotonEmitter emitter_;
  std::string name_;
};

}  // namespace

std::unique_ptr<PhotonBatchTracer> makeCpuPhotonTracer(const Scene& scene, const EmbreeAccel& accel) {
  return std::make_unique<CpuPhotonTracer<EmbreeTracer>>(scene, EmbreeTracer{&accel}, "cpu");
}

std::unique_ptr<PhotonBatchTracer> makeCpuPhotonTracer(const Scene& scene, const BvhView& bvh) {
  return std::make_unique<CpuPhotonTracer<BvhTracer>>(scene, BvhTracer{bvh}, "cpu (envgi BVH)");
}

void shootPhotons(const Scene& scene, const EmbreeAccel& accel, const PhotonShootSettings& s, PhotonMap* global,
                  PhotonMap* caustic, PhotonShootStats* stats) {
  if (s.tracer) return shootPhotons(scene, s, global, caustic, stats);
  PhotonShootSettings cpu = s;
  cpu.tracer = makeCpuPhotonTracer(scene, accel);
  shootPhotons(scene, cpu, global, caustic, stats);
}

void logPhotonStats(const PhotonShootStats& st) {
  spdlog::info("photon pass: {} global photons stored ({} emitted), {} caustic ({} emitted), {:.2f} s tracing on {}, "
               "{:.2f} s building kd-trees, {:.1f} MB ({} bytes a photon)",
               st.storedGlobal, st.emittedGlobal, st.storedCaustic, st.emittedCaustic, st.traceSeconds, st.device,
               st.buildSeconds, st.bytes / 1e6,
               st.storedGlobal + st.storedCaustic > 0 ? st.bytes / (st.storedGlobal + st.storedCaustic) : 0);
}

void shootPhotons(const Scene& scene, const PhotonShootSettings& s, PhotonMap* global, PhotonMap* caustic,
                  PhotonShootStats* stats) {
  using Clock = std::chrono::steady_clock;
  auto t0 = Clock::now();
  const SceneView& sc = scene.view();
  if (!s.tracer) throw std::logic_error("shootPhotons: no photon tracer");
  PhotonBatchTracer* tracer = s.tracer.get();
  bool anyLight = makePhotonEmitter(scene).emitsLight(sc);
  std::vector<Photon> g, c;
  bool gDone = s.globalPhotons == 0, cDone = s.causticPhotons == 0;
  uint64_t emitted = 0, gEmitted = 0, cEmitted = 0;
  // A scene without caustic paths never fills its caustic map: stop after a generous bound.
  const uint64_t cap = 64 * std::max(s.globalPhotons, s.causticPhotons) + 100000;
  double lastLog = 0.0;
  if (!anyLight) {
    spdlog::warn("the scene emits no light: no photons shot");
    gDone = cDone = true;
  }
  // A map still empty after 2^20 photons stays empty rather than spin on to the cap: no mirror
  // or glass leads light to a diffuse surface (caustic), or light reaches no second surface, a
  // lone object or floor (global, which keeps only photons after a bounce).
  auto giveUpIfEmpty = [&emitted](bool* done, const std::vector<Photon>& map, const char* paths, const char* name) {
    if (*done || !map.empty() || emitted < (uint64_t(1) << 20)) return;
    spdlog::info("no {} paths after {} photons: the {} map stays empty", paths, emitted, name);
    *done = true;
  };
  std::vector<PhotonBatch> batches;
  while (!(gDone && cDone) && emitted < cap) {
    PhotonTraceRequest req;
    req.first = emitted;
    req.seed = s.seed;
    req.maxDepth = s.maxDepth;
    req.global = !gDone;
    req.caustic = !cDone;
    tracer->trace(req, &batches);
    // Sub-batches are taken in order and the maps checked after each, whatever the device
    // traced at once: the same seed fills the same maps.
    for (PhotonBatch& b : batches) {
      if ((gDone && cDone) || emitted >= cap) break;
      if (!gDone) g.insert(g.end(), b.global.begin(), b.global.end());
      if (!cDone) c.insert(c.end(), b.caustic.begin(), b.caustic.end());
      emitted += uint64_t(kPhotonSubBatch);
      if (!gDone) gEmitted = emitted;
      if (!cDone) cEmitted = emitted;
      gDone = gDone || g.size() >= s.globalPhotons;
      cDone = cDone || c.size() >= s.causticPhotons;
      giveUpIfEmpty(&cDone, c, "caustic", "caustic");
      giveUpIfEmpty(&gDone, g, "indirect", "global");
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
    stats->device = tracer->deviceName();
  }
  // nanoflann (1.4 in Debian 12) builds a tree on one thread: the two maps' trees side by side.
  tbb::parallel_invoke([&] { global->build(std::move(g)); }, [&] { caustic->build(std::move(c)); });
  if (s.irradianceStride > 0) {
    auto precompute = [&](PhotonMap* map, float radius) {
      size_t n = map->beginIrradiance(s.irradianceStride);
      const std::vector<uint32_t> order = map->irradianceOrder();
      tbb::parallel_for(size_t(0), n, [&](size_t j) { map->estimateIrradiance(order[j], s.irradianceLookup, radius); });
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
