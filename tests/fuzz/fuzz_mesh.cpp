// libFuzzer target: mesh files. The first byte picks the reader: with its top bit set Mitsuba's
// serialized (its two low bits the shape_index), else PLY where it is even and OBJ where odd
// (the older seeds' meaning); the rest is the file. Errors must come as std::runtime_error;
// every reader validate()s what it returns.
#include <stdexcept>

#include "fuzz/FuzzInput.h"
#include "scene/TriangleMesh.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  if (size < 1) return 0;
  const int kind = (data[0] & 0x80) ? 2 : data[0] % 2;
  std::string path = envgi::fuzz::writeInput(data + 1, size - 1, kind == 0 ? ".ply" : kind == 1 ? ".obj" : ".serialized");
  try {
    if (kind == 0) (void)envgi::loadPly(path);
    else if (kind == 1) (void)envgi::loadObj(path);
    else (void)envgi::loadSerialized(path, data[0] & 3);
  } catch (const std::runtime_error&) {
  }
  return 0;
}
