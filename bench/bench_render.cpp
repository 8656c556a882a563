// The "Embree bound": envgi's path tracer in rays per second against a plain Embree loop
// tracing the very same rays (recorded from the path tracer), on the buddha scene, with 1 and
// 2 threads. The ratio is the share of time envgi spends outside Embree.
// Run: build/bin/envgi_bench_render --benchmark_repetitions=5 --benchmark_report_aggregates_only=true
// BM_ShareOfPlainEmbree gives the ratio itself from back-to-back pairs, robust to drift.
// BM_PlainEmbreeStreamsSameRays traces them through Embree's stream calls instead, as envgi does.
// ENVGI_BENCH_MESH=/path/to/mesh.ply swaps the Buddha for another mesh (e.g. the 871k dragon),
// ENVGI_BENCH_ENVMAP=/path/to/map.hdr Grace Cathedral for another map, ENVGI_BENCH_STRATEGY=S the
// map's sampling strategy (product, the scene's, for alias, importance, ...). ENVGI_BENCH_DEPTH=N cuts the
// paths at depth N instead of 4 (1: camera rays and the map they see; 2: one shading point), which
// splits the cost by depth.
#include <benchmark/benchmark.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cstdio>
#include <cstdlib>

#include "accel/EmbreeAccel.h"
#include "integrators/PathIntegrator.h"
#include "render/Renderer.h"
#include "scene/SceneLoader.h"

using namespace envgi;

namespace {

struct Recorded {
  std::vector<Ray> intersects, occlusions;
};

struct RecordingTracer {
  const EmbreeAccel* accel;
  Recorded* rec;
  bool intersect(const Ray& r, Hit* h) const {
    rec->intersects.push_back(r);
    return accel->intersect(r, h);
  }
  bool occluded(Vec3f o, Vec3f d, float tMax) const {
    rec->occlusions.push_back(Ray{o, d, tMax});
    return accel->occluded(o, d, tMax);
  }
};

// A depth that is not a positive integer ends the run with one line, not a silent depth 1.
int benchDepth() {
  const char* d = std::getenv("ENVGI_BENCH_DEPTH");
  if (!d) return 4;
  char* end = nullptr;
  long n = std::strtol(d, &end, 10);
  if (end == d || *end != '\0' || n < 1 || n > 1000) {
    std::fprintf(stderr, "error: ENVGI_BENCH_DEPTH must be a path depth from 1 to 1000, not '%s'\n", d);
    std::exit(2);
  }
  return int(n);
}

struct Fixture {
  Scene scene;
  std::unique_ptr<EmbreeAccel> accel;
  Recorded rec;
  Fixture() {
    std::map<std::string, std::string> defs = {{"res", "256"}, {"spp", "4"}};
    if (const char* m = std::getenv("ENVGI_BENCH_MESH")) defs["mesh"] = m;
    if (const char* e = std::getenv("ENVGI_BENCH_ENVMAP")) defs["envmap"] = e;
    if (const char* e = std::getenv("ENVGI_BENCH_STRATEGY")) defs["strategy"] = e;
    loadScene(std::string(ENVGI_SOURCE_DIR) + "/scenes/buddha.xml", defs, scene);
    scene.integrator.type = IntegratorType::Path;
    scene.integrator.path.maxDepth = benchDepth();
    scene.finalize();
    accel = std::make_unique<EmbreeAccel>(scene);
    // Record the rays of one full render, in the order the path tracer makes them.
    RecordingTracer tr{accel.get(), &rec};
    PathParams pp;
    pp.maxDepth = benchDepth();
    const Camera& cam = scene.view().camera;
    Sampler smp;
    smp.type = SamplerType::Sobol;
    smp.spp = 4;
    uint64_t rays = 0;
    for (int y = 0; y < cam.height; ++y)
      for (int x = 0; x < cam.width; ++x)
        for (uint32_t s = 0; s < 4; ++s) {
          smp.start(uint64_t(y) * cam.width + x, s);
          float w;  // the recorded rays do not depend on the filter's weight
          pathTrace(scene.view(), tr, sampleCameraRay(cam, smp, x, y, &w), smp, pp, &rays);
        }
  }
};

Fixture& fixture() {
  static Fixture f;
  return f;
}

// One envgi render of the fixture's scene; returns the rays it traced.
uint64_t renderEnvgi(Fixture& f, int threads) {
  RenderOptions o;
  o.progress = false;
  o.threads = threads;
  o.spp = 4;
  RenderStats st;
  Image img = render(f.scene, *f.accel, o, &st);
  benchmark::DoNotOptimize(img.rgb.data());
  return st.rays;
}

// The recorded rays through Embree's stream calls (rtcIntersect1M, rtcOccluded1M) in chunks of
// 256, as envgi's by-bounce loop traces a round's bounce and shadow rays: plain Embree at its
// best on these rays, for comparison with the one-ray loop below.
void tracePlainStreams(Fixture& f, tbb::task_arena& arena) {
  RTCScene scene = f.accel->handle();
  const auto& is = f.rec.intersects;
  const auto& os = f.rec.occlusions;
  std::atomic<uint64_t> hits{0};
  arena.execute([&] {
    tbb::parallel_for(tbb::blocked_range<size_t>(0, is.size(), 4096), [&](const tbb::blocked_range<size_t>& r) {
      RTCIntersectContext ctx;
      rtcInitIntersectContext(&ctx);
      std::vector<RTCRayHit> rh(256);
      uint64_t h = 0;
      for (size_t i0 = r.begin(); i0 < r.end(); i0 += 256) {
        const size_t n = std::min<size_t>(256, r.end() - i0);
        for (size_t k = 0; k < n; ++k) EmbreeAccel::fillRayHit(is[i0 + k], rh[k]);
        rtcIntersect1M(scene, &ctx, rh.data(), unsigned(n), sizeof(RTCRayHit));
        for (size_t k = 0; k < n; ++k) h += rh[k].hit.geomID != RTC_INVALID_GEOMETRY_ID;
      }
      hits += h;
    });
    tbb::parallel_for(tbb::blocked_range<size_t>(0, os.size(), 4096), [&](const tbb::blocked_range<size_t>& r) {
      RTCIntersectContext ctx;
      rtcInitIntersectContext(&ctx);
      std::vector<RTCRay> ray(256);
      for (size_t i0 = r.begin(); i0 < r.end(); i0 += 256) {
        const size_t n = std::min<size_t>(256, r.end() - i0);
        for (size_t k = 0; k < n; ++k) EmbreeAccel::fillRay(os[i0 + k], ray[k]);
        rtcOccluded1M(scene, &ctx, ray.data(), unsigned(n), sizeof(RTCRay));
      }
    });
  });
  benchmark::DoNotOptimize(hits.load());
}

// The recorded rays through a bare Embree loop, intersections then occlusions. Kept apart from
// the streams' loop above, as every stop since 21 has timed it.
void tracePlain(Fixture& f, tbb::task_arena& arena) {
  RTCScene scene = f.accel->handle();
  const auto& is = f.rec.intersects;
  const auto& os = f.rec.occlusions;
  std::atomic<uint64_t> hits{0};
  arena.execute([&] {
    tbb::parallel_for(tbb::blocked_range<size_t>(0, is.size(), 4096), [&](const tbb::blocked_range<size_t>& r) {
      RTCIntersectContext ctx;
      rtcInitIntersectContext(&ctx);
      uint64_t h = 0;
      for (size_t i = r.begin(); i < r.end(); ++i) {
        RTCRayHit rh{};
        EmbreeAccel::fillRayHit(is[i], rh);
        rtcIntersect1(scene, &ctx, &rh);
        h += rh.hit.geomID != RTC_INVALID_GEOMETRY_ID;
      }
      hits += h;
    });
    tbb::parallel_for(tbb::blocked_range<size_t>(0, os.size(), 4096), [&](const tbb::blocked_range<size_t>& r) {
      RTCIntersectContext ctx;
      rtcInitIntersectContext(&ctx);
      for (size_t i = r.begin(); i < r.end(); ++i) {
        RTCRay ray{};
        EmbreeAccel::fillRay(os[i], ray);
        rtcOccluded1(scene, &ctx, &ray);
      }
    });
  });
  benchmark::DoNotOptimize(hits.load());
}

}  // namespace

static void BM_EnvgiPathTracer(benchmark::State& state) {
  Fixture& f = fixture();
  uint64_t rays = 0;
  for (auto _ : state) rays += renderEnvgi(f, int(state.range(0)));
  state.counters["rays/s"] = benchmark::Counter(double(rays), benchmark::Counter::kIsRate);
}
BENCHMARK(BM_EnvgiPathTracer)->Arg(1)->Arg(2)->Unit(benchmark::kMillisecond)->UseRealTime();

static void BM_PlainEmbreeSameRays(benchmark::State& state) {
  Fixture& f = fixture();
  tbb::task_arena arena(int(state.range(0)));
  for (auto _ : state) tracePlain(f, arena);
  double rays = double(f.rec.intersects.size() + f.rec.occlusions.size());
  state.counters["rays/s"] = benchmark::Counter(rays * double(state.iterations()), benchmark::Counter::kIsRate);
  state.counters["rays"] = rays;
}
BENCHMARK(BM_PlainEmbreeSameRays)->Arg(1)->Arg(2)->Unit(benchmark::kMillisecond)->UseRealTime();

static void BM_PlainEmbreeStreamsSameRays(benchmark::State& state) {
  Fixture& f = fixture();
  tbb::task_arena arena(int(state.range(0)));
  for (auto _ : state) tracePlainStreams(f, arena);
  double rays = double(f.rec.intersects.size() + f.rec.occlusions.size());
  state.counters["rays/s"] = benchmark::Counter(rays * double(state.iterations()), benchmark::Counter::kIsRate);
}
BENCHMARK(BM_PlainEmbreeStreamsSameRays)->Arg(1)->Arg(2)->Unit(benchmark::kMillisecond)->UseRealTime();

// The figure directly: each iteration times an envgi render and the plain loop back to
// back, so that the machine's drift (10-15% within an hour here) hits both alike. "share" is the
// median over the iterations of plain time / envgi time, the fraction of Embree's rays/s envgi
// reaches; the benchmark's own time is the pair's.
static void BM_ShareOfPlainEmbree(benchmark::State& state) {
  Fixture& f = fixture();
  int threads = int(state.range(0));
  tbb::task_arena arena(threads);
  std::vector<double> shares;
  for (auto _ : state) {
    auto t0 = std::chrono::steady_clock::now();
    renderEnvgi(f, threads);
    auto t1 = std::chrono::steady_clock::now();
    tracePlain(f, arena);
    auto t2 = std::chrono::steady_clock::now();
    shares.push_back(std::chrono::duration<double>(t2 - t1).count() / std::chrono::duration<double>(t1 - t0).count());
  }
  std::sort(shares.begin(), shares.end());
  state.counters["share"] = shares.empty() ? 0.0 : shares[shares.size() / 2];
}
BENCHMARK(BM_ShareOfPlainEmbree)->Arg(1)->Arg(2)->Unit(benchmark::kMillisecond)->UseRealTime();

BENCHMARK_MAIN();
