// Linear RGB float images and their file formats (OpenEXR and stb_image underneath).
#pragma once

#include <utility>
#include <string>
#include <vector>

#include "core/Vec.h"

namespace envgi {

// One named channel beside an image's R, G, B (an AOV's "dd.T"): width x height floats, row-major.
struct ImageChannel {
  std::string name;
  std::vector<float> values;
};

struct Image {
  int width = 0, height = 0;
  std::vector<float> rgb;  // row-major, row 0 at the top, 3 floats a pixel
  // Further channels, which only OpenEXR holds: .exr files keep them both ways; a .png takes a
  // channel named A as its alpha; the other formats write the RGB alone.
  std::vector<ImageChannel> channels;

  Image() = default;
  Image(int w, int h) : width(w), height(h), rgb(size_t(w) * h * 3, 0.f) {}
  Color at(int x, int y) const {
    const float* p = &rgb[(size_t(y) * width + x) * 3];
    return {p[0], p[1], p[2]};
  }
  void set(int x, int y, Color c) {
    float* p = &rgb[(size_t(y) * width + x) * 3];
    p[0] = c.x;
    p[1] = c.y;
    p[2] = c.z;
  }
};

enum class ToneMap { Clamp, Aces };

struct SaveOptions {
  float exposure = 0.f;  // stops, applied before the tone curve (8-bit outputs only)
  ToneMap toneMap = ToneMap::Clamp;
  // String attributes of an OpenEXR header (how the image was made); other formats ignore them.
  std::vector<std::pair<std::string, std::string>> exrAttributes;
};

// Reads .exr (OpenEXR), .hdr, .png, .jpg (stb_image; 8-bit files are decoded from sRGB) and
// .pfm into linear RGB; throws std::runtime_error naming the file on a missing, unreadable or
// truncated file. decodeSrgb = false keeps 8-bit codes as code / 255 (Mitsuba's `raw`).
Image loadImage(const std::string& path, bool decodeSrgb = true);
// An OpenEXR file's string attributes, by name (what SaveOptions::exrAttributes wrote).
std::vector<std::pair<std::string, std::string>> exrStringAttributes(const std::string& path);
// Whether loadImage reads `path` as linear radiance (.exr, .pfm, .hdr), not as 8-bit display
// codes (.png, .jpg): what an error against a reference can be measured on.
bool holdsRadiance(const std::string& path);

// Writes by extension: .exr, .pfm and .hdr as linear float, .png/.jpg as 8-bit sRGB after
// exposure and tone curve. The file appears atomically (a temporary file, then rename).
void saveImage(const Image& img, const std::string& path, const SaveOptions& opts = {});
// The extensions saveImage writes by, lower-case.
const std::vector<std::string>& imageWriterExtensions();
// Threads that compress and decompress OpenEXR files (its scanline blocks in parallel); 0: one
// a core, the default. OpenEXR's own default is none: an 8192² render took 24 s to write.
void setImageThreads(int threads);

// Exposure, tone curve and sRGB encoding of one linear value, in [0,1].
float toneMapChannel(float v, const SaveOptions& opts);
// An 8-bit RGB buffer (3 bytes a pixel) encoded as PNG, in memory.
std::string encodePng(int width, int height, const std::vector<unsigned char>& rgb);
// 8-bit RGB as a baseline JPEG (quality 1-100), for streaming frames.
std::string encodeJpeg(int width, int height, const std::vector<unsigned char>& rgb, int quality);

// How many channel values are NaN or infinite.
size_t nonFiniteValues(const Image& img);
// Sets NaN, infinite and negative channel values to 0 (radiance that a light cannot have);
// returns how many there were.
size_t zeroInvalidRadiance(Image& img);

// The whole image as 8-bit sRGB, 3 bytes a pixel.
std::vector<unsigned char> toneMapImage(const Image& img, const SaveOptions& opts);

}  // namespace envgi
