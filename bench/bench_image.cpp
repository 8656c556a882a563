// Writing and reading a render's OpenEXR file (ZIP, float RGB), by OpenEXR's worker threads:
// Arg is the thread count handed to setImageThreads (1, then one a core).
// Run: build/bin/envgi_bench --benchmark_filter=Exr --benchmark_repetitions=3
#include <benchmark/benchmark.h>

#include <cmath>
#include <filesystem>
#include <thread>

#include "image/Image.h"
#include "sampling/Pcg32.h"

using namespace envgi;

namespace {
// A render-like 2048² image: smooth shading with per-pixel noise, which ZIP compresses as
// poorly as it does a real render's.
const Image& renderLike() {
  static const Image img = [] {
    Image im(2048, 2048);
    Pcg32 rng(7);
    for (int y = 0; y < im.height; ++y)
      for (int x = 0; x < im.width; ++x) {
        float base = 0.5f + 0.4f * std::sin(x * 0.01f) * std::cos(y * 0.013f);
        im.set(x, y, Color(base * (0.9f + 0.2f * rng.nextFloat()), base * 0.8f, base * (0.7f + 0.1f * rng.nextFloat())));
      }
    return im;
  }();
  return img;
}

std::string exrPath() { return (std::filesystem::temp_directory_path() / "envgi_bench_image.exr").string(); }

int threadsOf(const benchmark::State& state) {
  return state.range(0) > 0 ? int(state.range(0)) : int(std::max(1u, std::thread::hardware_concurrency()));
}
}  // namespace

static void BM_WriteExr2048(benchmark::State& state) {
  setImageThreads(threadsOf(state));
  for (auto _ : state) saveImage(renderLike(), exrPath());
  state.counters["threads"] = threadsOf(state);
  state.counters["Mpixels/s"] =
      benchmark::Counter(2048.0 * 2048.0 / 1e6 * double(state.iterations()), benchmark::Counter::kIsRate);
}
BENCHMARK(BM_WriteExr2048)->Arg(1)->Arg(0)->Unit(benchmark::kMillisecond)->UseRealTime();

static void BM_ReadExr2048(benchmark::State& state) {
  setImageThreads(threadsOf(state));
  saveImage(renderLike(), exrPath());
  for (auto _ : state) benchmark::DoNotOptimize(loadImage(exrPath()).rgb.data());
  state.counters["threads"] = threadsOf(state);
  state.counters["Mpixels/s"] =
      benchmark::Counter(2048.0 * 2048.0 / 1e6 * double(state.iterations()), benchmark::Counter::kIsRate);
}
BENCHMARK(BM_ReadExr2048)->Arg(1)->Arg(0)->Unit(benchmark::kMillisecond)->UseRealTime();
