// The cost of a draw from each sample sequence, in the pattern a path tracer asks for them:
// a pixel-filter pair, then per bounce a light choice, two light pairs, a BSDF lobe and pair and
// a roulette number. Run: build/bin/envgi_bench --benchmark_filter=Sampler
// A third argument of 1 asks as next-event estimation does in a scene lit by the map alone: the
// light choice and the second light pair are skipped, not drawn (the time per iteration is then
// comparable with the same sequence's, its draws per second are not).
#include <benchmark/benchmark.h>

#include "sampling/Pcg32.h"
#include "sampling/Sampler.h"
#include "scene/ReconstructionFilter.h"

using namespace envgi;

static void BM_SamplerDraws(benchmark::State& state) {
  Sampler smp;
  smp.type = SamplerType(state.range(0));
  smp.spp = uint32_t(state.range(1));
  const bool mapOnly = state.range(2) != 0;
  uint64_t pixel = 0, draws = 0;
  float acc = 0.f;
  for (auto _ : state) {
    for (uint32_t s = 0; s < smp.spp; ++s) {
      smp.start(pixel, s);
      Vec2f f = smp.get2D();
      acc += f.x + f.y;
      for (int bounce = 0; bounce < 3; ++bounce) {
        float sel = smp.get1DIf(!mapOnly);
        Vec2f l = smp.get2D(), l2 = smp.get2DIf(!mapOnly);
        float lobe = smp.get1D();
        Vec2f b = smp.get2D();
        acc += sel + l.x + l2.y + lobe + b.x + smp.get1D();
      }
      draws += mapOnly ? 13 : 19;
    }
    ++pixel;
  }
  benchmark::DoNotOptimize(acc);
  state.SetItemsProcessed(int64_t(draws));  // items/s: draws (1D or 2D) per second
}
// (type, spp, map only): independent, stratified, Sobol at 64 spp; Sobol at 83 (not a power of
// two); Sobol at 64 as a map-only scene asks.
BENCHMARK(BM_SamplerDraws)->Args({0, 64, 0})->Args({1, 64, 0})->Args({2, 64, 0})->Args({2, 83, 0})->Args({2, 64, 1});

// A pixel filter's draw: its offset and weight from a 2D sample, for each of Mitsuba's six
// filters (range 0 is the FilterType). Box, tent and gaussian are closed forms; the three with
// negative lobes search a 33-entry table an axis and evaluate their profile.
static void BM_SampleFilter(benchmark::State& state) {
  const ReconstructionFilter f = makeFilter(FilterType(state.range(0)));
  Pcg32 rng(7);
  float acc = 0.f;
  for (auto _ : state) {
    FilterSample s = sampleFilter(f, Vec2f(rng.nextFloat(), rng.nextFloat()));
    acc += s.offset.x + s.offset.y + s.weight;
  }
  benchmark::DoNotOptimize(acc);
  state.SetItemsProcessed(int64_t(state.iterations()));
}
BENCHMARK(BM_SampleFilter)->DenseRange(0, 5);
