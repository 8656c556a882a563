// Where the GPU test and benchmark find the bundled scenes: beside the binary in the package
// (share/envgi/scenes), or in the source tree they were built from.
#pragma once

#include <unistd.h>

#include <filesystem>
#include <string>

namespace envgi::test {

inline std::string bundledScenesDir() {
  namespace fs = std::filesystem;
  std::error_code ec;
  fs::path exe = fs::read_symlink("/proc/self/exe", ec);
  if (!ec) {
    fs::path packaged = exe.parent_path().parent_path() / "share/envgi/scenes";
    if (fs::exists(packaged / "buddha.xml")) return packaged.string();
  }
#ifdef ENVGI_SOURCE_DIR
  return std::string(ENVGI_SOURCE_DIR) + "/scenes";
#else
  return "scenes";
#endif
}

}  // namespace envgi::test
