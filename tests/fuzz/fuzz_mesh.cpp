// libFuzzer target: mesh files. The first byte picks PLY or OBJ; the rest is the file.
// Errors must come as std::runtime_error; both readers validate() what they return.
#include <stdexcept>

#include "fuzz/FuzzInput.h"
#include "scene/TriangleMesh.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  if (size < 1) return 0;
  bool ply = data[0] % 2 == 0;
  std::string path = envgi::fuzz::writeInput(data + 1, size - 1, ply ? ".ply" : ".obj");
  try {
    (void)(ply ? envgi::loadPly(path) : envgi::loadObj(path));
  } catch (const std::runtime_error&) {
  }
  return 0;
}
