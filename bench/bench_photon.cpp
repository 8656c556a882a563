// Photon mapping costs on the Cornell box: photons traced per second and the time of the
// first pass as the count grows (1e5 to 1e7), radiance lookups per second, bytes per stored
// photon, SPPM passes, and the grid integrator's frame time on the buddha at 512^2.
// Run: build/bin/envgi_bench_photon --benchmark_repetitions=3 --benchmark_report_aggregates_only=true
#include <benchmark/benchmark.h>
#include <tbb/task_arena.h>

#include "render/GridExecutor.h"
#include "render/Renderer.h"
#include "render/SppmExecutor.h"
#include "render/PhotonShooter.h"
#include "sampling/Pcg32.h"
#include "scene/SceneLoader.h"

using namespace envgi;

namespace {
struct Fixture {
  Scene scene;
  std::unique_ptr<EmbreeAccel> accel;
  Fixture() {
    loadScene(std::string(ENVGI_SOURCE_DIR) + "/scenes/cornell-box.xml", {{"res", "128"}}, scene);
    accel = std::make_unique<EmbreeAccel>(scene);
  }
};
Fixture& fixture() {
  static Fixture f;
  return f;
}
}  // namespace

static void BM_PhotonPass(benchmark::State& state) {
  Fixture& f = fixture();
  PhotonShootSettings ps;
  ps.globalPhotons = size_t(state.range(0));
  ps.causticPhotons = size_t(state.range(0)) / 4;
  ps.irradianceStride = 4;  // as the photon integrator's final gather needs
  ps.progress = false;
  PhotonShootStats st;
  for (auto _ : state) {
    PhotonMap g, c;
    shootPhotons(f.scene, *f.accel, ps, &g, &c, &st);
    benchmark::DoNotOptimize(g.size());
  }
  double stored = double(st.storedGlobal + st.storedCaustic);
  state.counters["stored"] = stored;
  state.counters["emitted"] = double(std::max(st.emittedGlobal, st.emittedCaustic));
  state.counters["emitted/s"] = double(std::max(st.emittedGlobal, st.emittedCaustic)) / st.traceSeconds;
  state.counters["trace_s"] = st.traceSeconds;
  state.counters["kdtree_irradiance_s"] = st.buildSeconds;
  state.counters["bytes/photon"] = double(st.bytes) / stored;
}
BENCHMARK(BM_PhotonPass)->Arg(100000)->Arg(1000000)->Arg(10000000)->Unit(benchmark::kMillisecond)->Iterations(1)->UseRealTime();

// The benchmark's iterations, each a whole photon pass on one thread; the last pass's stats.
static PhotonShootStats photonPassesOnOneThread(benchmark::State& state, const Scene& scene, const EmbreeAccel& accel,
                                                const PhotonShootSettings& ps) {
  PhotonShootStats st;
  tbb::task_arena one(1);
  for (auto _ : state) {
    PhotonMap g, c;
    one.execute([&] { shootPhotons(scene, accel, ps, &g, &c, &st); });
    benchmark::DoNotOptimize(g.size());
  }
  return st;
}

// The photon pass on the bundled glass teapot, one thread: photons from Grace Cathedral's
// 1024 x 512 map (an emission table of 6 MB), the caustic map's aimed at the two glass balls.
// Arg: photons asked of each map. The time is the whole pass (tracing, kd-trees, irradiance).
static void BM_PhotonPassTeapot(benchmark::State& state) {
  static Scene scene;
  static std::unique_ptr<EmbreeAccel> accel;
  if (!accel) {
    loadScene(std::string(ENVGI_SOURCE_DIR) + "/scenes/teapot-glass.xml", {{"res", "160"}}, scene);
    accel = std::make_unique<EmbreeAccel>(scene);
  }
  PhotonShootSettings ps;
  ps.globalPhotons = ps.causticPhotons = size_t(state.range(0));
  ps.irradianceStride = 4;
  ps.progress = false;
  PhotonShootStats st = photonPassesOnOneThread(state, scene, *accel, ps);
  state.counters["emitted_global"] = double(st.emittedGlobal);
  state.counters["emitted_caustic"] = double(st.emittedCaustic);
  state.counters["stored_caustic"] = double(st.storedCaustic);
  state.counters["emitted/s"] = double(st.emittedGlobal + st.emittedCaustic) / st.traceSeconds;
}
BENCHMARK(BM_PhotonPassTeapot)->Arg(20000)->Unit(benchmark::kMillisecond)->UseRealTime();

// The photon pass in the bundled Cornell box, one thread, 250,000 photons a map (the default),
// lit by its ceiling's area light. Arg: 1 aims the caustic photons at the two balls, 0 shoots
// them unaimed from the global map's stream.
static void BM_PhotonPassCornell(benchmark::State& state) {
  static Scene scene;
  static std::unique_ptr<EmbreeAccel> accel;
  if (!accel) {
    loadScene(std::string(ENVGI_SOURCE_DIR) + "/scenes/cornell-box.xml", {{"res", "160"}}, scene);
    accel = std::make_unique<EmbreeAccel>(scene);
  }
  PhotonShootSettings ps;
  ps.aimCaustics = state.range(0) != 0;
  ps.progress = false;
  PhotonShootStats st = photonPassesOnOneThread(state, scene, *accel, ps);
  state.counters["emitted_caustic"] = double(st.emittedCaustic);
  state.counters["stored_caustic"] = double(st.storedCaustic);
  state.counters["trace_s"] = st.traceSeconds;
}
BENCHMARK(BM_PhotonPassCornell)->Arg(0)->Arg(1)->Unit(benchmark::kMillisecond)->UseRealTime();

static void BM_RadianceLookup(benchmark::State& state) {
  Fixture& f = fixture();
  static PhotonMap g, c;
  if (g.size() == 0) {
    PhotonShootSettings ps;
    ps.globalPhotons = 1000000;
    ps.causticPhotons = 0;
    ps.progress = false;
    shootPhotons(f.scene, *f.accel, ps, &g, &c, nullptr);
  }
  const SceneView& sc = f.scene.view();
  PhotonLookup q;
  q.k = int(state.range(0));
  q.maxRadius = 0.1f;
  Pcg32 rng(3);
  const auto& ph = g.photons();
  Color acc(0.f);
  for (auto _ : state) {
    const Photon& p = ph[rng.nextUInt() % ph.size()];
    SurfaceInteraction si;
    si.p = p.p + Vec3f(0.01f * rng.nextFloat(), 0.f, 0.01f * rng.nextFloat());
    si.ng = p.n;
    si.shading = Frame::fromNormal(p.n);
    si.bsdf = 0;
    acc += g.estimate(sc, si, p.n, q);
  }
  benchmark::DoNotOptimize(acc);
  state.SetItemsProcessed(state.iterations());
}
BENCHMARK(BM_RadianceLookup)->Arg(50)->Arg(120);

// The photon integrator's second pass (camera rays, caustic lookups, final gather reading the
// irradiance cache) on the bundled glass teapot: 160 x 360, 4 spp, one thread. The time is the
// camera pass's alone (RenderStats), not the photon pass's before it.
static void BM_PhotonRenderTeapot(benchmark::State& state) {
  static Scene scene;
  static std::unique_ptr<EmbreeAccel> accel;
  if (!accel) {
    loadScene(std::string(ENVGI_SOURCE_DIR) + "/scenes/teapot-glass.xml", {{"res", "160"}}, scene);
    scene.integrator.type = IntegratorType::Photon;
    scene.finalize();
    accel = std::make_unique<EmbreeAccel>(scene);
  }
  RenderOptions o;
  o.progress = false;
  o.threads = 1;
  o.spp = 4;
  RenderStats st;
  for (auto _ : state) {
    Image img = render(scene, *accel, o, &st);
    benchmark::DoNotOptimize(img.rgb.data());
    state.SetIterationTime(st.seconds);
  }
  state.counters["Mrays/s"] = st.raysPerSecond() / 1e6;
}
BENCHMARK(BM_PhotonRenderTeapot)->Unit(benchmark::kMillisecond)->UseManualTime()->Iterations(3);

static void BM_SppmPass(benchmark::State& state) {
  Fixture& f = fixture();
  SppmParams s;
  s.photonsPerPass = size_t(state.range(0));
  SppmStats st;
  Progress quiet(1, false);
  for (auto _ : state) {
    SppmExecutor<EmbreeTracer> ex(f.scene, EmbreeTracer{f.accel.get()}, s, 0);
    PassCounters c;
    ex.runPass(0, 1, quiet, &c);
    st = ex.stats();
    benchmark::DoNotOptimize(c.rays);
  }
  state.counters["photons/s"] = double(s.photonsPerPass) / st.photonSeconds;
  state.counters["camera_s"] = st.cameraSeconds;
  state.counters["photon_s"] = st.photonSeconds;
}
BENCHMARK(BM_SppmPass)->Arg(100000)->Arg(1000000)->Unit(benchmark::kMillisecond)->UseRealTime();

// The grid integrator on the bundled buddha at 512^2: the one-off photon pass and grid fill,
// then milliseconds per 1-spp frame (the interactive cost once the grid exists).
static void BM_GridFrame(benchmark::State& state) {
  static Scene scene;
  static std::unique_ptr<EmbreeAccel> accel;
  static std::unique_ptr<GridExecutor<EmbreeTracer>> ex;
  if (!ex) {
    loadScene(std::string(ENVGI_SOURCE_DIR) + "/scenes/buddha.xml", {{"res", "512"}}, scene);
    scene.finalize();
    accel = std::make_unique<EmbreeAccel>(scene);
    GridExecutorSettings s;
    s.photons.globalPhotons = 200000;
    s.photons.causticPhotons = 50000;
    s.photons.irradianceStride = 4;
    s.photons.irradianceRadius = 0.05f * makePhotonEmitter(scene).radius;
    s.photons.causticIrradianceRadius = 0.25f * s.photons.irradianceRadius;
    s.photons.progress = false;
    s.photons.tracer = makeCpuPhotonTracer(scene, *accel);
    s.params.chain.strategy = EnvStrategy::Alias;
    SampleSequence seq{SamplerType::Sobol, 1024, 0};
    ex = std::make_unique<GridExecutor<EmbreeTracer>>(scene, EmbreeTracer{accel.get()}, s, seq, 0, false, 16);
  }
  Progress quiet(1, false);
  int frame = 0;
  PassCounters c;
  for (auto _ : state) {
    ex->runPass(frame, frame + 1, quiet, &c);
    ++frame;
  }
  state.counters["grid_fill_s"] = ex->build().gridStats.seconds;
  state.counters["photon_trace_s"] = ex->build().photonStats.traceSeconds;
  state.counters["Mrays/s"] = benchmark::Counter(double(c.rays) / 1e6, benchmark::Counter::kIsRate);
}
BENCHMARK(BM_GridFrame)->Unit(benchmark::kMillisecond)->UseRealTime();

BENCHMARK_MAIN();
