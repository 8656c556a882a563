#include "render/PhotonShooter.h"

#include <fmt/format.h>
#include <spdlog/spdlog.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_invoke.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <stdexcept>

#include "core/PhysicalMemory.h"
#include "render/Cancellation.h"

namespace envgi {

namespace {

// Whether a material can scatter a photon by a delta lobe (start a caustic): glass, mirrors,
// smooth plastic's coat, or a blend with one of these in it.
bool canScatterDelta(const std::vector<Bsdf>& bsdfs, int i, int depth = 0) {
  const Bsdf& b = bsdfs[size_t(i)];
  if (bsdfIsBlend(b))
    return depth < kMaxBlendDepth && (canScatterDelta(bsdfs, b.blend0, depth + 1) || canScatterDelta(bsdfs, b.blend1, depth + 1));
  return bsdfIsDelta(b) || b.type == BsdfType::Plastic;
}

struct BoundingSphere {
  Vec3f center;
  float radius;
};

// About the centre of the points' box, out to the farthest point (none: radius 0).
BoundingSphere boundPoints(const std::vector<Vec3f>& pts) {
  if (pts.empty()) return {Vec3f(0.f), 0.f};
  Vec3f lo(INFINITY), hi(-INFINITY);
  for (Vec3f p : pts) {
    lo = vmin(lo, p);
    hi = vmax(hi, p);
  }
  Vec3f c = (lo + hi) * 0.5f;
  float r2 = 0.f;
  for (Vec3f p : pts) r2 = fmaxf(r2, lengthSq(p - c));
  return {c, std::sqrt(r2)};
}

BoundingSphere boundSpheres(const BoundingSphere* s, size_t n) {
  Vec3f lo(INFINITY), hi(-INFINITY);
  for (size_t i = 0; i < n; ++i) {
    lo = vmin(lo, s[i].center - Vec3f(s[i].radius));
    hi = vmax(hi, s[i].center + Vec3f(s[i].radius));
  }
  Vec3f c = (lo + hi) * 0.5f;
  float r = 0.f;
  for (size_t i = 0; i < n; ++i) r = fmaxf(r, length(s[i].center - c) + s[i].radius);
  return {c, r};
}

// Bounding spheres of the shapes that can start a caustic, at most kMaxPhotonTargets (more are
// grouped along their widest axis), each widened a little against rounding.
std::vector<BoundingSphere> causticTargets(const Scene& scene) {
  std::vector<BoundingSphere> out;
  for (const ShapeEntry& e : scene.shapes) {
    if (!canScatterDelta(scene.bsdfs, e.bsdf)) continue;
    if (e.isSphere) {
      const Sphere& sp = scene.spheres[e.index];
      out.push_back({sp.center, sp.radius});
    } else if (e.isInstance) {
      // The prototype's box corners as placed: a bound without visiting every placed vertex.
      const MeshInstance& in = scene.instances[e.index];
      BoundingSphere local = boundPoints(scene.prototypes[size_t(in.prototype)].positions);
      std::vector<Vec3f> corners;
      for (int c = 0; c < 8; ++c)
        corners.push_back(in.toWorld.point(local.center + Vec3f(c & 1 ? local.radius : -local.radius,
                                                                c & 2 ? local.radius : -local.radius,
                                                                c & 4 ? local.radius : -local.radius)));
      out.push_back(boundPoints(corners));
    } else {
      out.push_back(boundPoints(scene.meshes[e.index].positions));
    }
  }
  if (out.size() > size_t(kMaxPhotonTargets)) {
    Vec3f lo(INFINITY), hi(-INFINITY);
    for (const BoundingSphere& b : out) {
      lo = vmin(lo, b.center);
      hi = vmax(hi, b.center);
    }
    Vec3f ext = hi - lo;
    int axis = ext.x >= ext.y && ext.x >= ext.z ? 0 : (ext.y >= ext.z ? 1 : 2);
    std::sort(out.begin(), out.end(), [axis](const BoundingSphere& a, const BoundingSphere& b) {
      return a.center[axis] < b.center[axis];
    });
    std::vector<BoundingSphere> groups;
    for (int g = 0; g < kMaxPhotonTargets; ++g) {
      size_t b = out.size() * size_t(g) / kMaxPhotonTargets, e = out.size() * size_t(g + 1) / kMaxPhotonTargets;
      groups.push_back(boundSpheres(out.data() + b, e - b));
    }
    out = std::move(groups);
  }
  // A shape with no extent (or none that is finite) can start no caustic anyone sees.
  std::vector<BoundingSphere> kept;
  for (BoundingSphere b : out) {
    b.radius = b.radius * 1.001f + 1e-6f * (length(b.center) + b.radius);
    if (b.radius > 0.f && std::isfinite(b.radius) && std::isfinite(length(b.center))) kept.push_back(b);
  }
  return kept;
}

}  // namespace

PhotonEmitter makePhotonEmitter(const Scene& scene, bool aim) {
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
  if (!aim) return e;
  // Aiming pays where the targets' disks are small beside the scene's: each aimed photon is
  // R^2 / sum r^2 times as likely to meet glass or a mirror first (from the map or a sun; from a
  // point or area light inside the scene, about as much).
  std::vector<BoundingSphere> targets = causticTargets(scene);
  double area = 0.0;
  for (const BoundingSphere& b : targets) area += double(b.radius) * b.radius;
  if (total > 0.0 && !targets.empty() && area > 0.0 && area <= 0.5 * double(e.radius) * e.radius) {
    double cdf = 0.0;
    for (const BoundingSphere& b : targets) {
      PhotonTarget& t = e.targets[e.targetCount++];
      double pick = double(b.radius) * b.radius / area;
      cdf += pick;
      t.center = b.center;
      t.radius = b.radius;
      t.pick = float(pick);
      t.cdf = float(cdf);
      t.density = float(pick / (kPi * double(b.radius) * b.radius));
    }
    e.targets[e.targetCount - 1].cdf = 1.f;
  }
  return e;
}

namespace {

template <class Tracer>
class CpuPhotonTracer final : public PhotonBatchTracer {
 public:
  CpuPhotonTracer(const Scene& scene, Tracer tracer, std::string name)
      : scene_(scene), tracer_(tracer), name_(std::move(name)) {}
  std::string deviceName() const override { return name_; }
  void trace(const PhotonTraceRequest& r, std::vector<PhotonBatch>* out) override {
    const int chunk = 1024, chunks = kPhotonSubBatch / chunk;
    std::vector<PhotonBatch> local(static_cast<size_t>(chunks));
    const SceneView& sc = scene_.view();
    tbb::parallel_for(0, chunks, [&](int ci) {
      PhotonBatch& b = local[size_t(ci)];
      const uint32_t stream = r.seed ^ r.stream;
      const uint64_t first = r.first + uint64_t(ci) * chunk;
      shootInPrefetchedBlocks(
          first, first + chunk,
          [&](uint64_t j) {
            Sampler smp = photonSampler(stream, j, 0);
            r.emitter.prefetch(sc, smp);
          },
          [&](uint64_t j) {
            shootPhoton(sc, tracer_, r.emitter, stream, j, 0, r.maxDepth, r.aimed,
                        [&](const SurfaceInteraction& si, Vec3f wi, Color pw, bool isCaustic, int) {
                          if (isCaustic ? r.caustic : r.global)
                            (isCaustic ? b.caustic : b.global).push_back(makePhoton(si, wi, pw));
                        });
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

void requirePhotonMapsFit(size_t photons, double memoryBytes) {
  const double bytes = double(photons) * double(kPhotonPeakBytes);
  requireFitsInHalfOfMemory(bytes, memoryBytes, fmt::format("photon maps of {} photons would take about", photons),
                            "ask for fewer photons (the integrator's global_photons and caustic_photons, or --global "
                            "and --caustic on envgi photons)");
}

void logPhotonStats(const PhotonShootStats& st) {
  std::string aimed = st.causticTargets > 0 ? fmt::format(", aimed at {} specular shapes", st.causticTargets) : "";
  spdlog::info("photon pass: {} global photons stored ({} emitted), {} caustic ({} emitted{}), {:.2f} s tracing on {}, "
               "{:.2f} s building kd-trees, {:.1f} MB ({} bytes a photon)",
               st.storedGlobal, st.emittedGlobal, st.storedCaustic, st.emittedCaustic, aimed, st.traceSeconds, st.device,
               st.buildSeconds, st.bytes / 1e6,
               st.storedGlobal + st.storedCaustic > 0 ? st.bytes / (st.storedGlobal + st.storedCaustic) : 0);
}

namespace {

using Clock = std::chrono::steady_clock;

// The photons the streams have stored in each map so far, how many photons each map's stream
// emitted, and when the pass began and last logged.
struct PhotonHarvest {
  std::vector<Photon> global, caustic;
  uint64_t globalEmitted = 0, causticEmitted = 0;
  Clock::time_point start = Clock::now();
  double lastLog = 0.0;
};

// Shoots one stream into the maps whose done flag is given (null: that map's photons are not
// this stream's) until each is full, given up or `cap` photons are emitted.
void fillFromStream(const PhotonShootSettings& s, PhotonBatchTracer* tracer, const PhotonEmitter& emitter,
                    uint32_t stream, bool aimed, uint64_t cap, PhotonHarvest* h, bool* globalDone, bool* causticDone) {
  std::vector<Photon>& g = h->global;
  std::vector<Photon>& c = h->caustic;
  std::vector<PhotonBatch> batches;
  uint64_t emitted = 0;
  // A map still empty after 2^20 photons stays empty rather than spin on to the cap: no mirror
  // or glass leads light to a diffuse surface (caustic), or light reaches no second surface, a
  // lone object or floor (global, which keeps only photons after a bounce).
  auto giveUpIfEmpty = [&emitted](bool* done, const std::vector<Photon>& map, const char* paths, const char* name) {
    if (*done || !map.empty() || emitted < (uint64_t(1) << 20)) return;
    spdlog::info("no {} paths after {} photons: the {} map stays empty", paths, emitted, name);
    *done = true;
  };
  bool gd = !globalDone || *globalDone, cd = !causticDone || *causticDone;
  while (!(gd && cd) && emitted < cap) {
    PhotonTraceRequest req;
    req.first = emitted;
    req.seed = s.seed;
    req.stream = stream;
    req.aimed = aimed;
    req.maxDepth = s.maxDepth;
    req.global = !gd;
    req.caustic = !cd;
    req.emitter = emitter;
    throwIfCancelled(s.cancel);
    tracer->trace(req, &batches);
    // Sub-batches are taken in order and the maps checked after each, whatever the device
    // traced at once: the same seed fills the same maps.
    for (PhotonBatch& b : batches) {
      if ((gd && cd) || emitted >= cap) break;
      if (!gd) g.insert(g.end(), b.global.begin(), b.global.end());
      if (!cd) c.insert(c.end(), b.caustic.begin(), b.caustic.end());
      emitted += uint64_t(kPhotonSubBatch);
      if (!gd) h->globalEmitted = emitted;
      if (!cd) h->causticEmitted = emitted;
      gd = gd || g.size() >= s.globalPhotons;
      cd = cd || c.size() >= s.causticPhotons;
      giveUpIfEmpty(&cd, c, "caustic", "caustic");
      giveUpIfEmpty(&gd, g, "indirect", "global");
    }
    double t = std::chrono::duration<double>(Clock::now() - h->start).count();
    if (s.progress && t - h->lastLog >= 2.0) {
      h->lastLog = t;
      spdlog::info("photon pass{}: {} emitted, {}/{} global, {}/{} caustic stored, {:.1f} s",
                   aimed ? " (caustics, aimed)" : "", emitted, g.size(), s.globalPhotons, c.size(), s.causticPhotons,
                   t);
    }
  }
  if (globalDone) *globalDone = gd;
  if (causticDone) *causticDone = cd;
}

// The maps' kd-trees, and their irradiance estimates where s asks for them.
void buildMaps(const PhotonShootSettings& s, std::vector<Photon> g, std::vector<Photon> c, PhotonMap* global,
               PhotonMap* caustic) {
  // nanoflann (1.4 in Debian 12) builds a tree on one thread: the two maps' trees side by side.
  tbb::parallel_invoke([&] { global->build(std::move(g)); }, [&] { caustic->build(std::move(c)); });
  if (s.irradianceStride <= 0) return;
  auto precompute = [&](PhotonMap* map, float radius) {
    size_t n = map->beginIrradiance(s.irradianceStride);
    const std::vector<uint32_t> order = map->irradianceOrder();
    tbb::parallel_for(size_t(0), n, [&](size_t j) { map->estimateIrradiance(order[j], s.irradianceLookup, radius); });
    map->endIrradiance();
  };
  precompute(global, s.irradianceRadius);
  precompute(caustic, s.causticIrradianceRadius);
}

}  // namespace

void shootPhotons(const Scene& scene, const PhotonShootSettings& s, PhotonMap* global, PhotonMap* caustic,
                  PhotonShootStats* stats) {
  PhotonHarvest h;
  const SceneView& sc = scene.view();
  if (!s.tracer) throw std::logic_error("shootPhotons: no photon tracer");
  requirePhotonMapsFit(s.globalPhotons + s.causticPhotons, physicalMemoryBytes());
  PhotonBatchTracer* tracer = s.tracer.get();
  PhotonEmitter emitter = makePhotonEmitter(scene, s.aimCaustics);
  bool gDone = s.globalPhotons == 0, cDone = s.causticPhotons == 0;
  // A scene without caustic paths never fills its caustic map: stop after a generous bound.
  const uint64_t cap = 64 * std::max(s.globalPhotons, s.causticPhotons) + 100000;
  if (!emitter.emitsLight(sc)) {
    spdlog::warn("the scene emits no light: no photons shot");
    gDone = cDone = true;
  }
  // One stream fills both maps; or, with targets to aim at, the global map's stream keeps only
  // its global photons and a second, aimed stream fills the caustic map.
  bool aim = emitter.targetCount > 0 && !cDone;  // targets only where s.aimCaustics
  if (!aim) {
    fillFromStream(s, tracer, emitter, kPhotonMapStream, false, cap, &h, &gDone, &cDone);
  } else {
    fillFromStream(s, tracer, emitter, kPhotonMapStream, false, cap, &h, &gDone, nullptr);
    fillFromStream(s, tracer, emitter, kCausticPhotonStream, true, cap, &h, nullptr, &cDone);
  }
  for (Photon& p : h.global) p.power = p.power / float(std::max<uint64_t>(h.globalEmitted, 1));
  for (Photon& p : h.caustic) p.power = p.power / float(std::max<uint64_t>(h.causticEmitted, 1));
  auto t1 = Clock::now();
  if (stats) {
    stats->emittedGlobal = h.globalEmitted;
    stats->emittedCaustic = h.causticEmitted;
    stats->storedGlobal = h.global.size();
    stats->storedCaustic = h.caustic.size();
    stats->causticTargets = aim ? emitter.targetCount : 0;
    stats->device = tracer->deviceName();
  }
  buildMaps(s, std::move(h.global), std::move(h.caustic), global, caustic);
  if (stats) {
    stats->traceSeconds = std::chrono::duration<double>(t1 - h.start).count();
    stats->buildSeconds = std::chrono::duration<double>(Clock::now() - t1).count();
    stats->bytes = global->bytes() + caustic->bytes();
  }
}

}  // namespace envgi
