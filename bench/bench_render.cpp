// The "Embree bound": envgi's path tracer in rays per second against a plain Embree loop
// tracing the very same rays (recorded from the path tracer), on the buddha scene, with 1 and
// 2 threads. The ratio is the share of time envgi spends outside Embree.
// Run: build/bin/envgi_bench_render --benchmark_repetitions=5 --benchmark_report_aggregates_only=true
// ENVGI_BENCH_MESH=/path/to/mesh.ply swaps the Buddha for another mesh (e.g. the 871k dragon),
// ENVGI_BENCH_ENVMAP=/path/to/map.hdr Grace Cathedral for another map, ENVGI_BENCH_DEPTH=N the path
// depth 4 for N (1: camera rays and the map seen directly, 2: one bounce; splits the cost by depth).
#include <benchmark/benchmark.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include <algorithm>
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

int benchDepth() {
  const char* d = std::getenv("ENVGI_BENCH_DEPTH");
  return d ? std::max(1, std::atoi(d)) : 4;
}

struct Fixture {
  Scene scene;
  std::unique_ptr<EmbreeAccel> accel;
  Recorded rec;
  Fixture() {
    std::map<std::string, std::string> defs = {{"res", "256"}, {"spp", "4"}};
    if (const char* m = std::getenv("ENVGI_BENCH_MESH")) defs["mesh"] = m;
    if (const char* e = std::getenv("ENVGI_BENCH_ENVMAP")) defs["envmap"] = e;
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
          Vec2f off = sampleFilter(cam.filter, smp.get2D());
          pathTrace(scene.view(), tr, cam.generateRay(x + 0.5f + off.x, y + 0.5f + off.y), smp, pp, &rays);
        }
  }
};

Fixture& fixture() {
  static Fixture f;
  return f;
}

}  // namespace

static void BM_EnvgiPathTracer(benchmark::State& state) {
  Fixture& f = fixture();
  RenderOptions o;
  o.progress = false;
  o.threads = int(state.range(0));
  o.spp = 4;
  uint64_t rays = 0;
  for (auto _ : state) {
    RenderStats st;
    Image img = render(f.scene, *f.accel, o, &st);
    benchmark::DoNotOptimize(img.rgb.data());
    rays += st.rays;
  }
  state.counters["rays/s"] = benchmark::Counter(double(rays), benchmark::Counter::kIsRate);
}
BENCHMARK(BM_EnvgiPathTracer)->Arg(1)->Arg(2)->Unit(benchmark::kMillisecond)->UseRealTime();

static void BM_PlainEmbreeSameRays(benchmark::State& state) {
  Fixture& f = fixture();
  tbb::task_arena arena(int(state.range(0)));
  RTCScene scene = f.accel->handle();
  const auto& is = f.rec.intersects;
  const auto& os = f.rec.occlusions;
  uint64_t rays = 0;
  for (auto _ : state) {
    std::atomic<uint64_t> hits{0};
    arena.execute([&] {
      tbb::parallel_for(tbb::blocked_range<size_t>(0, is.size(), 4096), [&](const tbb::blocked_range<size_t>& r) {
        RTCIntersectContext ctx;
        rtcInitIntersectContext(&ctx);
        uint64_t h = 0;
        for (size_t i = r.begin(); i < r.end(); ++i) {
          RTCRayHit rh{};
          rh.ray.org_x = is[i].o.x; rh.ray.org_y = is[i].o.y; rh.ray.org_z = is[i].o.z;
          rh.ray.dir_x = is[i].d.x; rh.ray.dir_y = is[i].d.y; rh.ray.dir_z = is[i].d.z;
          rh.ray.tnear = 0.f; rh.ray.tfar = is[i].tMax; rh.ray.mask = 0xFFFFFFFFu;
          rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
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
          ray.org_x = os[i].o.x; ray.org_y = os[i].o.y; ray.org_z = os[i].o.z;
          ray.dir_x = os[i].d.x; ray.dir_y = os[i].d.y; ray.dir_z = os[i].d.z;
          ray.tnear = 0.f; ray.tfar = os[i].tMax; ray.mask = 0xFFFFFFFFu;
          rtcOccluded1(scene, &ctx, &ray);
        }
      });
    });
    benchmark::DoNotOptimize(hits.load());
    rays += is.size() + os.size();
  }
  state.counters["rays/s"] = benchmark::Counter(double(rays), benchmark::Counter::kIsRate);
  state.counters["rays"] = double(is.size() + os.size());
}
BENCHMARK(BM_PlainEmbreeSameRays)->Arg(1)->Arg(2)->Unit(benchmark::kMillisecond)->UseRealTime();

BENCHMARK_MAIN();
