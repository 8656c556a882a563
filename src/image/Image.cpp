#include "image/Image.h"

#include "core/Files.h"

#include <fmt/format.h>
#include <ImfChannelList.h>
#include <ImfFrameBuffer.h>
#include <ImfHeader.h>
#include <ImfInputFile.h>
#include <ImfOutputFile.h>
#include <ImfStringAttribute.h>
#include <ImfThreading.h>
#include <openexr.h>
#include <stb/stb_image.h>
#include <stb/stb_image_write.h>
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <csetjmp>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <memory>
#include <mutex>
#include <thread>
#include <stdexcept>

// After <cstdio>: jpeglib.h needs FILE and size_t declared first.
#include <jpeglib.h>

namespace envgi {

namespace fs = std::filesystem;

namespace {

struct FileCloser {
  void operator()(FILE* f) const { std::fclose(f); }
};
using FilePtr = std::unique_ptr<FILE, FileCloser>;

// The first error OpenEXRCore reports while it reads a header (it may add a few more after it).
void keepFirstExrError(exr_const_context_t ctx, exr_result_t, const char* msg) {
  void* user = nullptr;
  if (exr_get_user_data(ctx, &user) == EXR_ERR_SUCCESS && user && static_cast<std::string*>(user)->empty())
    *static_cast<std::string*>(user) = msg ? msg : "";
}

// The header read by OpenEXRCore first, which checks each attribute's size against the file:
// the C++ InputFile believes it, and took 21 s and 1.9 GB over a 405-byte file whose string
// attribute claimed 1.98 GB (a fuzz input). Then the pixels the header promises against the
// file's bytes: even a constant image, zlib at its best ratio (about 1000:1) on half floats,
// holds fewer than 4096 pixels a byte, and a few hundred bytes whose dataWindow said 10 M x 2
// loaded as 240 MB of garbage. Both before anything large is allocated.
void checkExrHeader(const std::string& path) {
  std::string error;
  exr_context_initializer_t init = EXR_DEFAULT_CONTEXT_INITIALIZER;
  init.error_handler_fn = keepFirstExrError;
  init.user_data = &error;
  exr_context_t ctx = nullptr;
  exr_attr_box2i_t dw{};
  exr_result_t r = exr_start_read(&ctx, path.c_str(), &init);
  if (r == EXR_ERR_SUCCESS) r = exr_get_data_window(ctx, 0, &dw);
  exr_finish(&ctx);
  // An attribute of impossible size is reported through the handler, yet the read may still
  // "succeed" (it skips the attribute): a damaged file either way.
  if (r != EXR_ERR_SUCCESS || !error.empty())
    throw std::runtime_error(fmt::format("cannot read image '{}': {}", path,
                                         error.empty() ? exr_get_default_error_message(r) : error));
  const int64_t w = int64_t(dw.max.x) - dw.min.x + 1, h = int64_t(dw.max.y) - dw.min.y + 1;
  if (w <= 0 || h <= 0) throw std::runtime_error("image '" + path + "' has no pixels");
  std::error_code ec;
  const uintmax_t fileBytes = fs::file_size(path, ec);
  if (!ec && uintmax_t(w) * uintmax_t(h) > 4096 * fileBytes)
    throw std::runtime_error(fmt::format("image '{}': its header claims {} x {} pixels, more than its {} bytes can hold",
                                         path, w, h, fileBytes));
}

// OpenEXR's worker threads, set once before the first file unless setImageThreads came first.
std::once_flag g_exrThreadsSet;
void setExrThreads(int threads) {
  Imf::setGlobalThreadCount(threads > 0 ? threads : int(std::max(1u, std::thread::hardware_concurrency())));
}
void useExrThreads() { std::call_once(g_exrThreadsSet, [] { setExrThreads(0); }); }

// OpenEXR (as pbrt-v4 and Mitsuba 3 read it): R, G, B as float, or Y alone as grey.
Image loadExr(const std::string& path) {
  checkExrHeader(path);
  useExrThreads();
  try {
    Imf::InputFile in(path.c_str());
    const Imath::Box2i dw = in.header().dataWindow();
    const int w = dw.max.x - dw.min.x + 1, h = dw.max.y - dw.min.y + 1;  // > 0: checkExrHeader
    const Imf::ChannelList& ch = in.header().channels();
    bool rgb = ch.findChannel("R") && ch.findChannel("G") && ch.findChannel("B");
    bool grey = !rgb && ch.findChannel("Y");
    if (!rgb && !grey) throw std::runtime_error("image '" + path + "' has neither R, G, B nor Y channels");
    Image img(w, h);
    Imf::FrameBuffer fb;
    char* base = reinterpret_cast<char*>(img.rgb.data()) -
                 (ptrdiff_t(dw.min.x) + ptrdiff_t(dw.min.y) * w) * ptrdiff_t(3 * sizeof(float));
    size_t xs = 3 * sizeof(float), ys = xs * size_t(w);
    const char* names[3] = {"R", "G", "B"};
    for (int k = 0; k < 3; ++k)
      fb.insert(grey ? "Y" : names[k], Imf::Slice(Imf::FLOAT, base + k * sizeof(float), xs, ys));
    // Every other channel (an AOV's), by name, as float.
    for (Imf::ChannelList::ConstIterator it = ch.begin(); it != ch.end(); ++it) {
      std::string name = it.name();
      if (name == "R" || name == "G" || name == "B" || (grey && name == "Y")) continue;
      if (it.channel().xSampling != 1 || it.channel().ySampling != 1) continue;
      img.channels.push_back({name, std::vector<float>(size_t(w) * size_t(h), 0.f)});
    }
    for (ImageChannel& c : img.channels) {
      char* cb = reinterpret_cast<char*>(c.values.data()) -
                 (ptrdiff_t(dw.min.x) + ptrdiff_t(dw.min.y) * w) * ptrdiff_t(sizeof(float));
      fb.insert(c.name, Imf::Slice(Imf::FLOAT, cb, sizeof(float), sizeof(float) * size_t(w)));
    }
    in.setFrameBuffer(fb);
    in.readPixels(dw.min.y, dw.max.y);
    return img;
  } catch (const std::runtime_error&) {
    throw;
  } catch (const std::exception& e) {
    throw std::runtime_error("cannot read image '" + path + "': " + e.what());
  }
}

// stb_image for .hdr, .png and .jpg. stb pads a truncated file with zeros rather than failing
// (and its HDR run-length decoder never ends on zeros), so reads go through callbacks that note
// a read past the end and answer it with 0xFF bytes, on which the HDR decoder ends within a
// scanline. The padding is bounded, since a JPEG's marker search skips 0xFF bytes forever and
// a PNG's chunk skipping would run through gigabytes of it; after it comes the end of file.
struct StbStream {
  FILE* f;
  bool pastEnd = false;
  size_t padded = 0;
};
constexpr size_t kStbPadding = size_t(1) << 16;
int stbRead(void* user, char* data, int size) {
  auto* s = static_cast<StbStream*>(user);
  size_t n = std::fread(data, 1, size_t(size), s->f);
  if (n == 0 && size > 0) {
    s->pastEnd = true;
    if (s->padded >= kStbPadding) return 0;
    s->padded += size_t(size);
    std::memset(data, 0xFF, size_t(size));
    return size;
  }
  return int(n);
}
void stbSkip(void* user, int n) { std::fseek(static_cast<StbStream*>(user)->f, n, SEEK_CUR); }
int stbEof(void* user) { return std::feof(static_cast<StbStream*>(user)->f); }

// stb reads a Radiance header line by line until a blank one and, answered with padding past
// the end, would look for it forever; and it allocates the pixels that the resolution line
// names before reading them. So the header is checked here first: it must end inside the file,
// and the bytes after it must be able to hold the pixels (a run-length scanline takes at least
// 4 bytes and 2 per 127 pixels of each of its 4 channels; a flat one 4 bytes a pixel).
void checkRadianceHeader(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::string head(size_t(1) << 16, '\0');
  in.read(head.data(), std::streamsize(head.size()));
  head.resize(size_t(in.gcount()));
  auto bad = [&](const std::string& what) { return std::runtime_error("cannot read image '" + path + "': " + what); };
  size_t blank = head.find("\n\n");
  if (blank == std::string::npos) throw bad("the Radiance header does not end (truncated?)");
  size_t lineStart = blank + 2, lineEnd = head.find('\n', lineStart);
  if (lineEnd == std::string::npos) throw bad("the Radiance header has no resolution line (truncated?)");
  long long h = 0, w = 0;
  std::string res = head.substr(lineStart, lineEnd - lineStart);
  // Other layouts than "-Y h +X w" are left to stb, which names them unsupported.
  if (std::sscanf(res.c_str(), "-Y %lld +X %lld", &h, &w) != 2) return;
  if (w <= 0 || h <= 0) throw std::runtime_error("image '" + path + "' has no pixels");
  std::error_code ec;
  uintmax_t size = fs::file_size(path, ec);
  uintmax_t left = ec || size < lineEnd + 1 ? 0 : size - (lineEnd + 1);
  uintmax_t perRow = w >= 8 && w < 32768 ? 4 + 8 * uintmax_t((w + 126) / 127) : 4 * uintmax_t(w);
  if (left / perRow < uintmax_t(h)) throw bad("file is truncated");
}

Image loadStb(const std::string& path, bool hdr, bool decodeSrgb) {
  if (hdr) checkRadianceHeader(path);
  FilePtr f(std::fopen(path.c_str(), "rb"));
  if (!f) throw std::runtime_error("cannot open image '" + path + "'");
  StbStream s{f.get()};
  stbi_io_callbacks cb{stbRead, stbSkip, stbEof};
  int w = 0, h = 0, nc = 0;
  float* data = hdr ? stbi_loadf_from_callbacks(&cb, &s, &w, &h, &nc, 3) : nullptr;
  stbi_uc* ldr = hdr ? nullptr : stbi_load_from_callbacks(&cb, &s, &w, &h, &nc, 3);
  std::unique_ptr<float, void (*)(void*)> holdF(data, stbi_image_free);
  std::unique_ptr<stbi_uc, void (*)(void*)> holdL(ldr, stbi_image_free);
  if (!data && !ldr) throw std::runtime_error("cannot read image '" + path + "': " + stbi_failure_reason());
  if (s.pastEnd) throw std::runtime_error("cannot read image '" + path + "': file is truncated");
  // stb accepts a header's zero width ("+X 0") and returns an empty buffer.
  if (w <= 0 || h <= 0) throw std::runtime_error("image '" + path + "' has no pixels");
  Image img(w, h);
  size_t n = size_t(w) * h * 3;
  if (data) {
    std::memcpy(img.rgb.data(), data, n * sizeof(float));
  } else {
    // 8-bit files are sRGB-encoded: decode to linear, unless the caller wants the raw codes.
    for (size_t i = 0; i < n; ++i) {
      float c = ldr[i] / 255.f;
      img.rgb[i] = !decodeSrgb ? c : c <= 0.04045f ? c / 12.92f : std::pow((c + 0.055f) / 1.055f, 2.4f);
    }
  }
  return img;
}

// PFM (Netpbm's float format, small enough to read and write here): "PF" (RGB) or "Pf" (grey),
// size, scale whose sign gives the byte order (negative: little-endian), rows bottom first.
Image loadPfm(const std::string& path) {
  FilePtr f(std::fopen(path.c_str(), "rb"));
  if (!f) throw std::runtime_error("cannot open image '" + path + "'");
  char magic[3] = {0, 0, 0};
  int w = 0, h = 0;
  float scale = 0.f;
  if (std::fscanf(f.get(), "%2s %d %d %f", magic, &w, &h, &scale) != 4 || magic[0] != 'P' ||
      (magic[1] != 'F' && magic[1] != 'f'))
    throw std::runtime_error("cannot read image '" + path + "': not a PFM file");
  if (w <= 0 || h <= 0 || size_t(w) * size_t(h) > (size_t(1) << 31) || scale == 0.f || !std::isfinite(scale))
    throw std::runtime_error("cannot read image '" + path + "': bad PFM header");
  if (std::fgetc(f.get()) == EOF) throw std::runtime_error("cannot read image '" + path + "': file is truncated");
  int nc = magic[1] == 'F' ? 3 : 1;
  bool swap = scale > 0.f;  // big-endian data on this little-endian host
  // The header's size against the bytes that follow it, before allocating: a short file with
  // a large header would otherwise reserve gigabytes.
  long start = std::ftell(f.get());
  std::error_code ec;
  uintmax_t fileSize = fs::file_size(path, ec);
  if (ec || start < 0 || fileSize < uintmax_t(start) ||
      (fileSize - uintmax_t(start)) / (sizeof(float) * nc) < uintmax_t(w) * uintmax_t(h))
    throw std::runtime_error("cannot read image '" + path + "': file is truncated");
  std::vector<float> raw(size_t(w) * h * nc);
  if (std::fread(raw.data(), sizeof(float), raw.size(), f.get()) != raw.size())
    throw std::runtime_error("cannot read image '" + path + "': file is truncated");
  if (swap)
    for (float& v : raw) {
      uint32_t b;
      std::memcpy(&b, &v, 4);
      b = __builtin_bswap32(b);
      std::memcpy(&v, &b, 4);
    }
  Image img(w, h);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      const float* p = &raw[(size_t(h - 1 - y) * w + x) * nc];
      img.set(x, y, nc == 3 ? Color(p[0], p[1], p[2]) : Color(p[0]));
    }
  return img;
}

bool writePfm(const Image& img, const fs::path& path) {
  FilePtr f(std::fopen(path.c_str(), "wb"));
  if (!f) return false;
  std::fprintf(f.get(), "PF\n%d %d\n-1.0\n", img.width, img.height);
  bool ok = true;
  for (int y = img.height - 1; y >= 0 && ok; --y)
    ok = std::fwrite(&img.rgb[size_t(y) * img.width * 3], sizeof(float), size_t(img.width) * 3, f.get()) ==
         size_t(img.width) * 3;
  return std::fclose(f.release()) == 0 && ok;
}

bool writeExr(const Image& img, const fs::path& path, const SaveOptions& opts) {
  useExrThreads();
  Imf::Header header(img.width, img.height);
  header.compression() = Imf::ZIP_COMPRESSION;
  for (const auto& [name, value] : opts.exrAttributes) header.insert(name, Imf::StringAttribute(value));
  const char* names[3] = {"R", "G", "B"};
  Imf::FrameBuffer fb;
  size_t xs = 3 * sizeof(float), ys = xs * size_t(img.width);
  for (int k = 0; k < 3; ++k) {
    header.channels().insert(names[k], Imf::Channel(Imf::FLOAT));
    fb.insert(names[k], Imf::Slice(Imf::FLOAT, (char*)(img.rgb.data() + k), xs, ys));
  }
  for (const ImageChannel& c : img.channels) {
    if (c.values.size() != size_t(img.width) * size_t(img.height))
      throw std::runtime_error("channel '" + c.name + "' does not match the image's size");
    if (header.channels().findChannel(c.name)) throw std::runtime_error("channel '" + c.name + "' given twice");
    header.channels().insert(c.name, Imf::Channel(Imf::FLOAT));
    fb.insert(c.name, Imf::Slice(Imf::FLOAT, (char*)c.values.data(), sizeof(float), sizeof(float) * size_t(img.width)));
  }
  Imf::OutputFile out(path.c_str(), header);
  out.setFrameBuffer(fb);
  out.writePixels(img.height);
  return true;
}

}  // namespace

void setImageThreads(int threads) {
  std::call_once(g_exrThreadsSet, [] {});
  setExrThreads(threads);
}

bool holdsRadiance(const std::string& path) {
  const std::string ext = lowerExtension(path);
  return ext == ".exr" || ext == ".pfm" || ext == ".hdr" || ext == ".pic";
}

Image loadImage(const std::string& path, bool decodeSrgb) {
  if (!fs::exists(path)) throw std::runtime_error("cannot open image '" + path + "': no such file");
  std::string ext = lowerExtension(path);
  if (ext == ".exr") return loadExr(path);
  if (ext == ".pfm") return loadPfm(path);
  if (ext == ".hdr" || ext == ".pic") return loadStb(path, true, false);
  if (ext == ".png" || ext == ".jpg" || ext == ".jpeg") return loadStb(path, false, decodeSrgb);
  throw std::runtime_error("cannot read image '" + path + "': unknown format '" + ext +
                           "' (envgi reads .exr, .hdr, .pfm, .png, .jpg)");
}

namespace {

// Exposure (as a factor) and tone curve of one linear value, clamped to [0,1].
float toneCurve(float v, float scale, ToneMap curve) {
  if (!(v > 0.f)) return 0.f;  // also maps NaN to black
  v *= scale;
  if (curve == ToneMap::Aces) {
    // Narkowicz's fit of the ACES filmic curve; past 1e4 it is above 1 (and inf / inf is NaN).
    v = std::min(v, 1e4f);
    v = (v * (2.51f * v + 0.03f)) / (v * (2.43f * v + 0.59f) + 0.14f);
  }
  return std::clamp(v, 0.f, 1.f);
}

// The 8-bit sRGB code of a linear value in [0,1], lround(srgb(v) * 255) but for float rounding at
// a step, without a pow a channel (which made the viewer's tone map 11 ms of a 512^2 frame).
// t[k] is the linear value where code k+1 begins (srgb(v) * 255 >= k + 0.5), t[255] = inf.
// start[] holds the code at the start of each of 128 buckets an octave (by the float's bits)
// from 2^-13 to 1; no bucket holds two steps, so one comparison finishes the lookup.
struct SrgbSteps {
  static constexpr int kBucketBits = 7, kOctaves = 13;
  float t[256];
  unsigned char start[(kOctaves << kBucketBits) + 1];
  uint32_t lowBits;
  SrgbSteps() {
    for (int k = 1; k <= 255; ++k) {
      double s = (k - 0.5) / 255.0;
      t[k - 1] = float(s <= 0.04045 ? s / 12.92 : std::pow((s + 0.055) / 1.055, 2.4));
    }
    t[255] = INFINITY;
    const float low = std::ldexp(1.f, -kOctaves);
    std::memcpy(&lowBits, &low, 4);
    for (size_t b = 0; b < sizeof(start); ++b) {
      uint32_t bits = lowBits + uint32_t(b << (23 - kBucketBits));
      float v;
      std::memcpy(&v, &bits, 4);
      start[b] = (unsigned char)(std::upper_bound(t, t + 255, v) - t);
    }
  }
  unsigned char code(float v) const {
    uint32_t bits;
    std::memcpy(&bits, &v, 4);
    if (bits < lowBits) return 0;  // below t[0], and 0 itself
    int c = start[(bits - lowBits) >> (23 - kBucketBits)];
    return (unsigned char)(c + (v >= t[c]));
  }
};

}  // namespace

float toneMapChannel(float v, const SaveOptions& opts) {
  v = toneCurve(v, std::exp2(opts.exposure), opts.toneMap);
  return v <= 0.0031308f ? 12.92f * v : 1.055f * std::pow(v, 1.f / 2.4f) - 0.055f;
}

// stb_image_write's output callback, into a std::string.
static void appendTo(void* ctx, void* data, int size) {
  static_cast<std::string*>(ctx)->append(static_cast<char*>(data), size_t(size));
}

std::string encodePng(int width, int height, const std::vector<unsigned char>& rgb) {
  std::string out;
  if (!stbi_write_png_to_func(appendTo, &out, width, height, 3, rgb.data(), width * 3))
    throw std::runtime_error("cannot encode a PNG");
  return out;
}

namespace {
// libjpeg reports errors by calling error_exit, which must not return: jump back to encodeJpeg.
struct JpegError {
  jpeg_error_mgr mgr;
  std::jmp_buf back;
  char message[JMSG_LENGTH_MAX];
};
[[noreturn]] void jpegErrorExit(j_common_ptr c) {
  auto* e = reinterpret_cast<JpegError*>(c->err);
  c->err->format_message(c, e->message);
  std::longjmp(e->back, 1);
}
}  // namespace

// libjpeg-turbo (SIMD) rather than stb_image_write: 512^2 in about a fifth of stb's time, which
// was most of a viewer frame from the GPU.
std::string encodeJpeg(int width, int height, const std::vector<unsigned char>& rgb, int quality) {
  if (width <= 0 || height <= 0 || rgb.size() < size_t(width) * size_t(height) * 3)
    throw std::runtime_error("cannot encode a JPEG: the buffer does not hold the image");
  jpeg_compress_struct c{};
  JpegError err{};
  c.err = jpeg_std_error(&err.mgr);
  err.mgr.error_exit = jpegErrorExit;
  unsigned char* mem = nullptr;
  unsigned long memSize = 0;
  if (setjmp(err.back)) {
    jpeg_destroy_compress(&c);
    std::free(mem);
    throw std::runtime_error(std::string("cannot encode a JPEG: ") + err.message);
  }
  jpeg_create_compress(&c);
  jpeg_mem_dest(&c, &mem, &memSize);
  c.image_width = JDIMENSION(width);
  c.image_height = JDIMENSION(height);
  c.input_components = 3;
  c.in_color_space = JCS_RGB;
  jpeg_set_defaults(&c);
  jpeg_set_quality(&c, std::clamp(quality, 1, 100), TRUE);
  jpeg_start_compress(&c, TRUE);
  while (c.next_scanline < c.image_height) {
    JSAMPROW row = const_cast<unsigned char*>(rgb.data() + size_t(c.next_scanline) * size_t(width) * 3);
    jpeg_write_scanlines(&c, &row, 1);
  }
  jpeg_finish_compress(&c);
  std::string out(reinterpret_cast<char*>(mem), memSize);
  jpeg_destroy_compress(&c);
  std::free(mem);
  return out;
}

size_t nonFiniteValues(const Image& img) {
  size_t n = 0;
  for (float v : img.rgb) n += !std::isfinite(v);
  return n;
}

size_t zeroInvalidRadiance(Image& img) {
  size_t n = 0;
  for (float& v : img.rgb)
    if (!std::isfinite(v) || v < 0.f) v = 0.f, ++n;
  return n;
}

std::vector<unsigned char> toneMapImage(const Image& img, const SaveOptions& opts) {
  static const SrgbSteps steps;
  const float scale = std::exp2(opts.exposure);
  std::vector<unsigned char> ldr(img.rgb.size());
  tbb::parallel_for(tbb::blocked_range<size_t>(0, ldr.size(), 1 << 14), [&](const tbb::blocked_range<size_t>& r) {
    for (size_t i = r.begin(); i != r.end(); ++i) ldr[i] = steps.code(toneCurve(img.rgb[i], scale, opts.toneMap));
  });
  return ldr;
}

const std::vector<std::string>& imageWriterExtensions() {
  static const std::vector<std::string> exts = {".exr", ".pfm", ".hdr", ".png", ".jpg", ".jpeg"};
  return exts;
}

std::vector<std::pair<std::string, std::string>> exrStringAttributes(const std::string& path) {
  checkExrHeader(path);
  Imf::InputFile in(path.c_str());
  std::vector<std::pair<std::string, std::string>> out;
  for (auto it = in.header().begin(); it != in.header().end(); ++it)
    if (auto* a = dynamic_cast<const Imf::StringAttribute*>(&it.attribute())) out.emplace_back(it.name(), a->value());
  return out;
}

void saveImage(const Image& img, const std::string& path, const SaveOptions& opts) {
  fs::path p(path);
  std::string ext = lowerExtension(path);
  if (ext.empty()) throw std::runtime_error("output '" + path + "' has no extension to choose a format by");
  const std::vector<std::string>& known = imageWriterExtensions();
  if (std::find(known.begin(), known.end(), ext) == known.end())
    throw std::runtime_error("cannot write '" + path + "': no writer for '" + ext +
                             "' (envgi writes .exr, .pfm, .hdr, .png, .jpg)");
  requireWritableDirectoryOf(path);
  // Hidden, so a crash leaves no look-alike; renamed into place only once complete.
  fs::path tmp = temporarySibling(path, ext);
  bool ok = false;
  std::string err;
  try {
    if (ext == ".pfm") {
      ok = writePfm(img, tmp);
    } else if (ext == ".exr") {
      ok = writeExr(img, tmp, opts);
    } else if (ext == ".hdr") {
      ok = stbi_write_hdr(tmp.c_str(), img.width, img.height, 3, img.rgb.data()) != 0;
    } else {
      std::vector<unsigned char> ldr = toneMapImage(img, opts);
      if (ext == ".png") {
        // A channel named A (the film's alpha) makes an RGBA PNG: coverage, not tone mapped.
        const ImageChannel* alpha = nullptr;
        for (const ImageChannel& c : img.channels)
          if (c.name == "A" && c.values.size() == size_t(img.width) * size_t(img.height)) alpha = &c;
        if (alpha) {
          std::vector<unsigned char> rgba(size_t(img.width) * size_t(img.height) * 4);
          for (size_t i = 0; i < alpha->values.size(); ++i) {
            for (int k = 0; k < 3; ++k) rgba[4 * i + size_t(k)] = ldr[3 * i + size_t(k)];
            float a = std::clamp(alpha->values[i], 0.f, 1.f);
            rgba[4 * i + 3] = (unsigned char)std::lround(a * 255.f);
          }
          ok = stbi_write_png(tmp.c_str(), img.width, img.height, 4, rgba.data(), img.width * 4) != 0;
        } else {
          ok = stbi_write_png(tmp.c_str(), img.width, img.height, 3, ldr.data(), img.width * 3) != 0;
        }
      } else {
        std::string jpg = encodeJpeg(img.width, img.height, ldr, 95);
        std::ofstream f(tmp, std::ios::binary);
        f.write(jpg.data(), std::streamsize(jpg.size()));
        ok = bool(f.flush());
      }
    }
  } catch (const std::exception& e) {
    ok = false;
    err = e.what();
  }
  if (!ok) {
    std::error_code ec;
    fs::remove(tmp, ec);
    throw std::runtime_error("cannot write '" + path + "': " + (err.empty() ? "write failed" : err));
  }
  renameIntoPlace(tmp.string(), path);
}

}  // namespace envgi
