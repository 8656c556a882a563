// Option checks for the command line (cli/Commands.h).
#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <stdexcept>

#include "cli/Commands.h"
#include "core/Files.h"
#include "image/Image.h"
#include "render/WorkerThreads.h"

namespace envgi::cli {

bool parseFiniteNumber(const std::string& s, double& v) {
  char* end = nullptr;
  v = std::strtod(s.c_str(), &end);
  return !s.empty() && end == s.c_str() + s.size() && std::isfinite(v);
}

CLI::Validator atLeast(double lo) {
  return CLI::Validator(
      [lo](std::string& s) -> std::string {
        double v = 0;
        if (!parseFiniteNumber(s, v)) return fmt::format("'{}' is not a number", s);
        if (v < lo) return fmt::format("must be at least {}, not {}", lo, s);
        return "";
      },
      fmt::format("NUMBER >= {}", lo));
}

CLI::Validator finiteNumber() {
  return CLI::Validator(
      [](std::string& s) -> std::string {
        double v = 0;
        if (!parseFiniteNumber(s, v)) return fmt::format("'{}' is not a finite number", s);
        return "";
      },
      "NUMBER");
}

CLI::Validator wholeNumberFrom(long long lo, long long hi) {
  return CLI::Validator(
      [lo, hi](std::string& s) -> std::string {
        double v = 0;
        if (!parseFiniteNumber(s, v) || v != std::floor(v)) return fmt::format("'{}' is not a whole number", s);
        if (v < double(lo) || v > double(hi)) return fmt::format("must be from {} to {}, not {}", lo, hi, s);
        return "";
      },
      fmt::format("{}..{}", lo, hi));
}

void addThreadsOption(CLI::App* c, int* threads) {
  c->add_option("--threads", *threads, fmt::format("Worker threads, 0 for every core (the default), at most {}",
                                                   kMaxWorkerThreads))
      ->check(wholeNumberFrom(0, kMaxWorkerThreads))
      // Every oneTBB loop, and OpenEXR's reads and writes (maps, images, checkpoints), keep to it.
      ->each([](const std::string& s) {
        limitWorkerThreads(int(std::stod(s)));
        setImageThreads(int(std::stod(s)));
      });
}

std::string requireOutputExtension(const std::string& path, const std::vector<std::string>& allowed,
                                   const std::string& what) {
  const std::string e = lowerExtension(path);  // as saveImage chooses its format
  if (std::find(allowed.begin(), allowed.end(), e) == allowed.end()) {
    std::string list;
    for (size_t i = 0; i < allowed.size(); ++i)
      list += (i == 0 ? "" : i + 1 == allowed.size() ? " or " : ", ") + allowed[i];
    throw std::runtime_error(fmt::format("{} '{}' must end in {}", what, path, list));
  }
  requireWritableDirectoryOf(path);
  return e;
}

void requireRadianceImage(const std::string& path, const std::string& who) {
  if (holdsRadiance(path)) return;
  throw std::runtime_error(fmt::format(
      "{} measures radiance, and '{}' is not a radiance image: give the .exr, .pfm or .hdr (a render's --png is "
      "tone-mapped and clamped)",
      who, path));
}

}  // namespace envgi::cli
