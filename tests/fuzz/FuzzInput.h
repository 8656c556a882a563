// The fuzz targets read their input through the loaders' own file paths, so each input is
// written to a file first: in /dev/shm where it exists, keyed by the process id so that
// parallel fuzzing jobs do not share one.
#pragma once

#include <spdlog/spdlog.h>
#include <unistd.h>

#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <string>

namespace envgi::fuzz {

// Warnings about the inputs (NaN texels, unknown properties) would be most of the run time.
inline const bool kQuietLog = (spdlog::set_level(spdlog::level::err), true);

inline std::string writeInput(const uint8_t* data, size_t size, const std::string& ext) {
  namespace fs = std::filesystem;
  fs::path dir = fs::exists("/dev/shm") ? fs::path("/dev/shm") : fs::temp_directory_path();
  std::string path = (dir / ("envgi-fuzz-" + std::to_string(getpid()) + ext)).string();
  FILE* f = std::fopen(path.c_str(), "wb");
  if (!f) std::abort();
  if (size) std::fwrite(data, 1, size, f);
  std::fclose(f);
  return path;
}

}  // namespace envgi::fuzz
