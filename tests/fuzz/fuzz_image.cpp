// libFuzzer target: image files (loadImage) and the map built from one (EnvironmentMap).
// The first byte picks the format; the rest is the file. A loader may throw
// std::runtime_error for bad input; anything else (a crash, a sanitizer report, a huge
// allocation, a hang) is a defect.
#include <stdexcept>

#include "envmap/EnvironmentMap.h"
#include "fuzz/FuzzInput.h"
#include "image/Image.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  if (size < 1) return 0;
  static const char* kExt[] = {".exr", ".pfm", ".hdr", ".png", ".jpg"};
  std::string path = envgi::fuzz::writeInput(data + 1, size - 1, kExt[data[0] % 5]);
  envgi::Image img;
  try {
    img = envgi::loadImage(path);
  } catch (const std::runtime_error&) {
    return 0;
  }
  // A map's tables grow with its pixels; small images are enough to reach every check.
  if (size_t(img.width) * img.height > (1u << 16)) return 0;
  try {
    envgi::EnvironmentMap map(std::move(img), {});
    (void)map.stats();
  } catch (const std::runtime_error&) {
  }
  return 0;
}
