// The cost of a draw from each sample sequence, in the pattern a path tracer asks for them:
// a pixel-filter pair, then per bounce a light choice, two light pairs, a BSDF lobe and pair and
// a roulette number. Run: build/bin/envgi_bench --benchmark_filter=Sampler
#include <benchmark/benchmark.h>

#include "sampling/Sampler.h"

using namespace envgi;

static void BM_SamplerDraws(benchmark::State& state) {
  Sampler smp;
  smp.type = SamplerType(state.range(0));
  smp.spp = uint32_t(state.range(1));
  uint64_t pixel = 0, draws = 0;
  float acc = 0.f;
  for (auto _ : state) {
    for (uint32_t s = 0; s < smp.spp; ++s) {
      smp.start(pixel, s);
      Vec2f f = smp.get2D();
      acc += f.x + f.y;
      for (int bounce = 0; bounce < 3; ++bounce) {
        float sel = smp.get1D();
        Vec2f l = smp.get2D(), l2 = smp.get2D();
        float lobe = smp.get1D();
        Vec2f b = smp.get2D();
        acc += sel + l.x + l2.y + lobe + b.x + smp.get1D();
      }
      draws += 19;
    }
    ++pixel;
  }
  benchmark::DoNotOptimize(acc);
  state.SetItemsProcessed(int64_t(draws));  // items/s: draws (1D or 2D) per second
}
// (type, spp): independent, stratified, Sobol at 64 spp; Sobol at 83 (not a power of two).
BENCHMARK(BM_SamplerDraws)->Args({0, 64})->Args({1, 64})->Args({2, 64})->Args({2, 83});
