#include "image/Image.h"

#include "core/Files.h"

#include <OpenImageIO/imageio.h>

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <stdexcept>
#include <unistd.h>

namespace envgi {

namespace fs = std::filesystem;
using OIIO::ImageInput;
using OIIO::ImageOutput;
using OIIO::ImageSpec;
using OIIO::TypeDesc;

Image loadImage(const std::string& path) {
  if (!fs::exists(path)) throw std::runtime_error("cannot open image '" + path + "': no such file");
  auto in = ImageInput::open(path);
  if (!in) {
    std::string err = OIIO::geterror();
    throw std::runtime_error("cannot read image '" + path + "': " + (err.empty() ? "unknown format" : err));
  }
  const ImageSpec& spec = in->spec();
  int w = spec.width, h = spec.height, nc = spec.nchannels;
  if (w <= 0 || h <= 0 || nc <= 0) throw std::runtime_error("image '" + path + "' has no pixels");
  std::vector<float> raw(size_t(w) * h * nc);
  bool ok = in->read_image(0, 0, 0, nc, TypeDesc::FLOAT, raw.data());
  std::string err = in->geterror();
  in->close();
  if (!ok || !err.empty())
    throw std::runtime_error("cannot read image '" + path + "': " + (err.empty() ? "read failed (truncated?)" : err));
  Image img(w, h);
  for (size_t i = 0; i < size_t(w) * h; ++i) {
    const float* p = &raw[i * nc];
    img.rgb[i * 3 + 0] = p[0];
    img.rgb[i * 3 + 1] = nc >= 3 ? p[1] : p[0];
    img.rgb[i * 3 + 2] = nc >= 3 ? p[2] : p[0];
  }
  return img;
}

float toneMapChannel(float v, const SaveOptions& opts) {
  if (!(v > 0.f)) return 0.f;  // also maps NaN to black
  v *= std::exp2(opts.exposure);
  if (opts.toneMap == ToneMap::Aces) {
    // Narkowicz's fit of the ACES filmic curve.
    v = (v * (2.51f * v + 0.03f)) / (v * (2.43f * v + 0.59f) + 0.14f);
  }
  v = std::clamp(v, 0.f, 1.f);
  return v <= 0.0031308f ? 12.92f * v : 1.055f * std::pow(v, 1.f / 2.4f) - 0.055f;
}

namespace {

// OpenImageIO 2.4 reads PFM but cannot write it: the format is small enough to write here
// (Netpbm spec: "PF", size, negative scale = little-endian, rows bottom first).
bool writePfm(const Image& img, const fs::path& path) {
  FILE* f = std::fopen(path.c_str(), "wb");
  if (!f) return false;
  std::fprintf(f, "PF\n%d %d\n-1.0\n", img.width, img.height);
  bool ok = true;
  for (int y = img.height - 1; y >= 0 && ok; --y)
    ok = std::fwrite(&img.rgb[size_t(y) * img.width * 3], sizeof(float), size_t(img.width) * 3, f) ==
         size_t(img.width) * 3;
  return std::fclose(f) == 0 && ok;
}

}  // namespace

void saveImage(const Image& img, const std::string& path, const SaveOptions& opts) {
  fs::path p(path);
  std::string ext = p.extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(), ::tolower);
  bool isFloat = ext == ".exr" || ext == ".pfm" || ext == ".hdr";
  if (ext.empty()) throw std::runtime_error("output '" + path + "' has no extension to choose a format by");
  fs::path dir = p.has_parent_path() ? p.parent_path() : fs::path(".");
  if (!fs::is_directory(dir)) throw std::runtime_error("cannot write '" + path + "': directory does not exist");
  // Same extension so OpenImageIO picks the same writer; hidden so a crash leaves no look-alike.
  fs::path tmp = temporarySibling(path, ext);

  auto commit = [&] {
    std::error_code ec;
    fs::rename(tmp, p, ec);
    if (ec) {
      fs::remove(tmp, ec);
      throw std::runtime_error("cannot write '" + path + "': rename failed");
    }
  };
  if (ext == ".pfm") {
    if (!writePfm(img, tmp)) {
      std::error_code ec;
      fs::remove(tmp, ec);
      throw std::runtime_error("cannot write '" + path + "'");
    }
    return commit();
  }
  auto out = ImageOutput::create(tmp.string());
  if (!out) throw std::runtime_error("cannot write '" + path + "': no writer for '" + ext + "'");
  ImageSpec spec(img.width, img.height, 3, isFloat ? TypeDesc::FLOAT : TypeDesc::UINT8);
  if (ext == ".exr") spec.attribute("compression", "zip");
  bool ok = out->open(tmp.string(), spec);
  if (ok) {
    if (isFloat) {
      ok = out->write_image(TypeDesc::FLOAT, img.rgb.data());
    } else {
      std::vector<unsigned char> ldr(img.rgb.size());
      for (size_t i = 0; i < ldr.size(); ++i)
        ldr[i] = (unsigned char)std::lround(toneMapChannel(img.rgb[i], opts) * 255.f);
      ok = out->write_image(TypeDesc::UINT8, ldr.data());
    }
  }
  std::string err = out->geterror();
  ok = out->close() && ok;
  if (!ok) {
    std::error_code ec;
    fs::remove(tmp, ec);
    throw std::runtime_error("cannot write '" + path + "': " + (err.empty() ? "write failed" : err));
  }
  commit();
}

}  // namespace envgi
