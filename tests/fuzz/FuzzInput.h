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

// The folder the inputs go to, made for this process and removed at its exit.
inline const std::filesystem::path& inputDir() {
  namespace fs = std::filesystem;
  struct Dir {
    fs::path path;
    Dir() {
      fs::path base = fs::exists("/dev/shm") ? fs::path("/dev/shm") : fs::temp_directory_path();
      path = base / ("envgi-fuzz-" + std::to_string(getpid()));
      fs::create_directories(path);
    }
    ~Dir() {
      std::error_code ec;
      fs::remove_all(path, ec);
    }
  };
  static Dir dir;
  return dir.path;
}

inline std::string writeInput(const uint8_t* data, size_t size, const std::string& ext) {
  std::string path = (inputDir() / ("input" + ext)).string();
  FILE* f = std::fopen(path.c_str(), "wb");
  if (!f) std::abort();
  if (size) std::fwrite(data, 1, size, f);
  std::fclose(f);
  return path;
}

}  // namespace envgi::fuzz
