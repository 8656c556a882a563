#include "render/SplitRender.h"

#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include <chrono>
#include <exception>
#include <stdexcept>
#include <thread>
#include <vector>

namespace envgi {

Image renderSplit(int width, int height, int spp, int shares, const RenderOptions& opts,
                  const SharePreparer& prepare, RenderStats* stats) {
  const int first = opts.firstSample, end = opts.sampleEnd < 0 ? spp : opts.sampleEnd;
  if (shares < 1) throw std::runtime_error("a render splits into one share or more");
  if (first < 0 || first >= end || end > spp)
    throw std::runtime_error(fmt::format("the samples {}:{} are not a range within the render's {}", first, end, spp));
  if (opts.varianceOut) throw std::runtime_error("a render split over devices keeps no per-pixel variance");
  shares = std::min(shares, end - first);
  const size_t px = size_t(width) * size_t(height);
  std::vector<FilmSums> films(static_cast<size_t>(shares));
  std::vector<std::vector<int>> counts(static_cast<size_t>(shares));
  std::vector<RenderStats> shareStats(static_cast<size_t>(shares));
  std::vector<std::exception_ptr> errors(static_cast<size_t>(shares));
  const auto t0 = std::chrono::steady_clock::now();
  {
    std::vector<std::jthread> threads;
    for (int i = 0; i < shares; ++i) {
      RenderOptions o = opts;
      o.firstSample = first + int(int64_t(end - first) * i / shares);
      o.sampleEnd = first + int(int64_t(end - first) * (i + 1) / shares);
      o.filmOut = &films[size_t(i)];
      o.samplesOut = &counts[size_t(i)];
      o.progress = false;
      o.progressFraction = nullptr;
      o.checkpoint = nullptr;
      o.checkpointSeconds = 0.0;
      threads.emplace_back([&, o, i] {
        try {
          PreparedRender pr = prepare(o, i);
          if (pr.spp != spp)
            throw std::logic_error(fmt::format("share {} renders {} spp, the split {}", i, pr.spp, spp));
          renderPasses(*pr.executor, width, height, pr.spp, o, &shareStats[size_t(i)]);
          spdlog::info("share {} ({}:{}) on {}: {:.2f} s", i, o.firstSample, o.sampleEnd, pr.executor->deviceName(),
                       shareStats[size_t(i)].seconds);
        } catch (...) {
          errors[size_t(i)] = std::current_exception();
        }
      });
    }
  }
  for (const std::exception_ptr& e : errors)
    if (e) std::rethrow_exception(e);
  // The films added up, each pixel over the samples its shares took (all of them, unless Ctrl-C
  // cut a share's last pass).
  FilmSums film = std::move(films[0]);
  std::vector<int> taken = std::move(counts[0]);
  for (int i = 1; i < shares; ++i) {
    const FilmSums& f = films[size_t(i)];
    for (size_t k = 0; k < px; ++k) film.sum[k] += f.sum[k];
    for (size_t k = 0; k < film.weightSum.size(); ++k) film.weightSum[k] += f.weightSum[k];
    for (size_t k = 0; k < film.sumSqLum.size(); ++k) film.sumSqLum[k] += f.sumSqLum[k];
    for (size_t k = 0; k < px; ++k) taken[k] += counts[size_t(i)][k];
  }
  if (opts.filmOut) *opts.filmOut = film;
  if (opts.samplesOut) *opts.samplesOut = taken;
  if (stats) {
    *stats = RenderStats{};
    stats->seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    stats->sppDone = end;
    for (const RenderStats& s : shareStats) {
      stats->rays += s.rays;
      stats->nonFiniteSamples += s.nonFiniteSamples;
      stats->pixelSamples += s.pixelSamples;
      stats->cancelled = stats->cancelled || s.cancelled;
      if (s.cancelled) stats->sppDone = std::min(stats->sppDone, s.sppDone);
    }
  }
  return filmMean(film, width, height, taken);
}

}  // namespace envgi
