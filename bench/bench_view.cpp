// The viewer's budgets on this machine: the time from a camera move to the first frame from
// the new camera (render 1 spp, tone map, JPEG), as the page sees it while orbiting, on the
// bundled scenes at 256^2 with path and with grid; the budget is 50 ms on 2 cores.
// Run: build/bin/envgi_bench_view --benchmark_repetitions=3 --benchmark_report_aggregates_only=true
#include <benchmark/benchmark.h>

#include <cmath>

#include "ViewOrbit.h"
#include "image/Image.h"

using namespace envgi;

static void BM_OrbitMoveToFrame(benchmark::State& state, const char* sceneName, const char* integrator) {
  ViewOptions vo;
  vo.maxSpp = 1;  // the orbiting case: one sample a pixel per camera
  bench::ViewOrbit orbit(std::string(ENVGI_SOURCE_DIR) + "/scenes/" + sceneName + ".xml", 256, integrator, vo);
  for (auto _ : state) orbit.moveAndWait();
  state.counters["jpeg_kB"] = double(orbit.lastJpegBytes()) / 1e3;
}
BENCHMARK_CAPTURE(BM_OrbitMoveToFrame, buddha_path, "buddha", "path")->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK_CAPTURE(BM_OrbitMoveToFrame, cornell_path, "cornell-box", "path")->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK_CAPTURE(BM_OrbitMoveToFrame, teapot_path, "teapot-glass", "path")->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK_CAPTURE(BM_OrbitMoveToFrame, buddha_grid, "buddha", "grid")->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK_CAPTURE(BM_OrbitMoveToFrame, cornell_grid, "cornell-box", "grid")->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK_CAPTURE(BM_OrbitMoveToFrame, buddha_direct, "buddha", "direct")->Unit(benchmark::kMillisecond)->UseRealTime();

// The frame's own cost at 512^2 (a GPU renders a 1-spp frame in about 1 ms): the tone map to
// 8-bit sRGB, against the per-channel pow it replaced, and the JPEG encode.
static Image noisyFrame() {
  Image img;
  img.width = img.height = 512;
  img.rgb.resize(size_t(3) * 512 * 512);
  uint32_t h = 1;
  for (float& v : img.rgb) {
    h = h * 1664525u + 1013904223u;
    v = std::exp2(float(h >> 8) / float(1 << 24) * 12.f - 9.f);  // 2^-9 .. 2^3
  }
  return img;
}
static void BM_ToneMap512(benchmark::State& state) {
  Image img = noisyFrame();
  for (auto _ : state) benchmark::DoNotOptimize(toneMapImage(img, {}));
}
static void BM_ToneMap512PerChannelPow(benchmark::State& state) {
  Image img = noisyFrame();
  std::vector<unsigned char> ldr(img.rgb.size());
  for (auto _ : state) {
    for (size_t i = 0; i < ldr.size(); ++i) ldr[i] = (unsigned char)std::lround(toneMapChannel(img.rgb[i], {}) * 255.f);
    benchmark::DoNotOptimize(ldr.data());
  }
}
static void BM_Jpeg512(benchmark::State& state) {
  Image img = noisyFrame();
  std::vector<unsigned char> ldr = toneMapImage(img, {});
  for (auto _ : state) benchmark::DoNotOptimize(encodeJpeg(512, 512, ldr, 85));
}
BENCHMARK(BM_ToneMap512)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_ToneMap512PerChannelPow)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_Jpeg512)->Unit(benchmark::kMillisecond)->UseRealTime();

BENCHMARK_MAIN();
