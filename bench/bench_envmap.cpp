// Building the sampling structures and drawing samples, per strategy.
// Run: build/bin/envgi_bench --benchmark_repetitions=5 --benchmark_report_aggregates_only=true
#include <benchmark/benchmark.h>

#include "envmap/EnvironmentMap.h"
#include "sampling/Pcg32.h"

using namespace envgi;

namespace {
Image syntheticMap(int w, int h) {
  Image img(w, h);
  Pcg32 rng(1);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      float sky = y < h / 2 ? 1.f : 0.2f;
      float sun = (std::abs(x - w / 3) < w / 256 && std::abs(y - h / 5) < h / 128) ? 5000.f : 0.f;
      img.set(x, y, Color(sky + sun + 0.1f * rng.nextFloat()));
    }
  return img;
}
}  // namespace

static void BM_BuildDistribution4096x2048(benchmark::State& state) {
  Image img = syntheticMap(4096, 2048);
  for (auto _ : state) {
    EnvironmentMap env(img, {});
    benchmark::DoNotOptimize(env.view().dist.marginal.funcInt);
  }
  state.counters["pixels"] = 4096.0 * 2048.0;
}
BENCHMARK(BM_BuildDistribution4096x2048)->Unit(benchmark::kMillisecond)->UseRealTime();

static void BM_Sample(benchmark::State& state) {
  static EnvironmentMap env(syntheticMap(4096, 2048), {});
  EnvironmentMapView v = env.view();
  EnvStrategy s = EnvStrategy(state.range(0));
  Vec3f normal = normalize(Vec3f(0.3f, 0.8f, -0.2f));  // cosine and product sample about it
  Pcg32 rng(7);
  float acc = 0.f;
  for (auto _ : state) {
    EnvSample es = v.sample(s, Vec2f(rng.nextFloat(), rng.nextFloat()), normal);
    acc += es.pdf;
  }
  benchmark::DoNotOptimize(acc);
  state.SetItemsProcessed(state.iterations());
  static const char* names[] = {"uniform", "cosine", "importance(binary search)", "alias", "adaptive", "points",
                                "product"};
  state.SetLabel(names[state.range(0)]);
}
BENCHMARK(BM_Sample)->DenseRange(0, 4)->Arg(6);

// Radiance from random directions (the bilinear lookup a ray that escapes makes).
static void BM_Eval(benchmark::State& state) {
  static EnvironmentMap env(syntheticMap(4096, 2048), {});
  EnvironmentMapView v = env.view();
  Pcg32 rng(9);
  Color acc(0.f);
  for (auto _ : state) {
    float z = 1.f - 2.f * rng.nextFloat(), phi = 2.f * kPi * rng.nextFloat(), r = std::sqrt(std::max(0.f, 1.f - z * z));
    acc += v.eval(Vec3f(r * std::cos(phi), r * std::sin(phi), z));
  }
  benchmark::DoNotOptimize(acc);
  state.SetItemsProcessed(state.iterations());
}
BENCHMARK(BM_Eval);

BENCHMARK_MAIN();
