#include <ImfChannelList.h>
#include <ImfFrameBuffer.h>
#include <ImfHeader.h>
#include <ImfOutputFile.h>
#include <ImfStringAttribute.h>
#include <gtest/gtest.h>

#include <cstring>
#include <random>

#include <filesystem>
#include <fstream>

#include "image/Image.h"
#include <stb/stb_image.h>

using namespace envgi;
namespace fs = std::filesystem;

namespace {
fs::path tmpDir() {
  static int counter = 0;
  fs::path d = fs::temp_directory_path() /
               ("envgi_image_test_" + std::to_string(::getpid()) + "_" + std::to_string(counter++));
  fs::create_directories(d);
  return d;
}
Image pattern() {
  Image img(5, 3);
  for (int y = 0; y < 3; ++y)
    for (int x = 0; x < 5; ++x) img.set(x, y, Color(x * 0.5f, y * 2.f, 100.f + x));
  return img;
}
}  // namespace

TEST(Image, FloatFormatsRoundTrip) {
  fs::path d = tmpDir();
  Image img = pattern();
  for (std::string ext : {".exr", ".pfm", ".hdr"}) {
    std::string p = (d / ("a" + ext)).string();
    saveImage(img, p);
    Image back = loadImage(p);
    ASSERT_EQ(back.width, 5);
    ASSERT_EQ(back.height, 3);
    float tol = ext == ".hdr" ? 0.01f : 1e-6f;
    for (int y = 0; y < 3; ++y)
      for (int x = 0; x < 5; ++x)
        for (int k = 0; k < 3; ++k)
          EXPECT_NEAR(back.at(x, y)[k], img.at(x, y)[k], tol * std::max(1.f, img.at(x, y)[k])) << ext;
  }
  fs::remove_all(d);
}

// toneMapImage finds the 8-bit code among the curve's steps; it must agree with rounding the
// channel curve, but for values within float rounding of a step.
TEST(Image, ToneMapImageMatchesTheRoundedChannelCurve) {
  Image img;
  img.width = 1000;
  img.height = 1000;
  img.rgb.resize(size_t(3) * img.width * img.height);
  std::mt19937 rng(5);
  std::uniform_real_distribution<float> e(-14.f, 6.f);
  for (float& v : img.rgb) v = std::exp2(e(rng));
  img.rgb[0] = NAN;
  img.rgb[1] = -1.f;
  img.rgb[2] = INFINITY;
  for (ToneMap curve : {ToneMap::Clamp, ToneMap::Aces})
    for (float exposure : {0.f, -1.5f, 2.f}) {
      SaveOptions o;
      o.toneMap = curve;
      o.exposure = exposure;
      std::vector<unsigned char> ldr = toneMapImage(img, o);
      size_t off = 0, far = 0;
      for (size_t i = 0; i < ldr.size(); ++i) {
        long want = std::lround(toneMapChannel(img.rgb[i], o) * 255.f);
        off += ldr[i] != want;
        far += std::abs(long(ldr[i]) - want) > 1;
      }
      EXPECT_EQ(far, 0u);
      EXPECT_LT(off, ldr.size() / 100000) << "exposure " << exposure;
      EXPECT_EQ(ldr[0], 0);
      EXPECT_EQ(ldr[1], 0);
      EXPECT_EQ(ldr[2], 255);
    }
}

// The viewer's frames: a JPEG that decodes (stb_image, an independent decoder) to the image
// given, within JPEG's loss on a smooth picture; a buffer too short for the size is an error.
TEST(Image, JpegDecodesBackToTheImage) {
  const int w = 67, h = 41;
  std::vector<unsigned char> rgb(size_t(w) * h * 3);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      unsigned char* p = &rgb[3 * (size_t(y) * w + x)];
      p[0] = (unsigned char)(255 * x / (w - 1));
      p[1] = (unsigned char)(255 * y / (h - 1));
      p[2] = 128;
    }
  std::string jpg = encodeJpeg(w, h, rgb, 90);
  int bw = 0, bh = 0, n = 0;
  unsigned char* back = stbi_load_from_memory(reinterpret_cast<const unsigned char*>(jpg.data()), int(jpg.size()),
                                              &bw, &bh, &n, 3);
  ASSERT_NE(back, nullptr);
  EXPECT_EQ(bw, w);
  EXPECT_EQ(bh, h);
  double sq = 0.0;
  int worst = 0;
  for (size_t i = 0; i < rgb.size(); ++i) {
    int d = std::abs(int(back[i]) - int(rgb[i]));
    sq += double(d) * d;
    worst = std::max(worst, d);
  }
  stbi_image_free(back);
  EXPECT_LT(std::sqrt(sq / double(rgb.size())), 2.0);
  EXPECT_LT(worst, 16);
  rgb.resize(rgb.size() - 1);
  EXPECT_THROW(encodeJpeg(w, h, rgb, 90), std::runtime_error);
  EXPECT_THROW(encodeJpeg(0, h, rgb, 90), std::runtime_error);
}

TEST(Image, PngIsSrgbAfterExposure) {
  EXPECT_NEAR(toneMapChannel(1.f, {}), 1.f, 1e-6f);
  EXPECT_NEAR(toneMapChannel(0.5f, {}), 0.7353569f, 1e-4f);
  SaveOptions o;
  o.exposure = 1.f;
  EXPECT_NEAR(toneMapChannel(0.25f, o), 0.7353569f, 1e-4f);
  EXPECT_EQ(toneMapChannel(NAN, {}), 0.f);
  o.toneMap = ToneMap::Aces;
  EXPECT_LT(toneMapChannel(100.f, o), 1.0001f);
  fs::path d = tmpDir();
  saveImage(pattern(), (d / "a.png").string());
  Image back = loadImage((d / "a.png").string());
  EXPECT_EQ(back.width, 5);
  fs::remove_all(d);
}

TEST(Image, MissingTruncatedAndCorruptFilesThrow) {
  fs::path d = tmpDir();
  EXPECT_THROW(loadImage((d / "nope.hdr").string()), std::runtime_error);
  // Garbage with an image extension.
  { std::ofstream f(d / "bad.exr"); f << "this is not an image"; }
  EXPECT_THROW(loadImage((d / "bad.exr").string()), std::runtime_error);
  // A real HDR cut in half.
  Image big(64, 32);
  for (size_t i = 0; i < big.rgb.size(); ++i) big.rgb[i] = float(i % 97) * 0.1f;
  saveImage(big, (d / "full.hdr").string());
  saveImage(big, (d / "full.pfm").string());
  saveImage(big, (d / "full.exr").string());
  for (std::string ext : {".hdr", ".pfm", ".exr"}) {
    auto size = fs::file_size(d / ("full" + ext));
    fs::copy_file(d / ("full" + ext), d / ("cut" + ext));
    fs::resize_file(d / ("cut" + ext), size / 2);
    EXPECT_THROW(loadImage((d / ("cut" + ext)).string()), std::runtime_error) << ext;
  }
  fs::remove_all(d);
}

// Each of these once hung, read out of bounds or reserved gigabytes for a few bytes of file
// (found by tests/fuzz); now each is an error naming the file.
TEST(Image, HeadersThatPromiseMoreThanTheFileHoldsThrow) {
  fs::path d = tmpDir();
  auto expectError = [&](const std::string& name, const std::string& content, const std::string& expect) {
    { std::ofstream(d / name, std::ios::binary) << content; }
    try {
      loadImage((d / name).string());
      ADD_FAILURE() << name << ": no error";
    } catch (const std::runtime_error& e) {
      EXPECT_NE(std::string(e.what()).find(expect), std::string::npos) << name << ": " << e.what();
    }
  };
  const std::string rgbe = "#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n";
  std::string pixels(24, '\x80');
  expectError("zero-width.hdr", rgbe + "-Y 2 +X 0\n" + pixels, "has no pixels");
  expectError("no-blank-line.hdr", "#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n-Y 2 +X 3\n" + pixels, "header does not end");
  expectError("huge.hdr", rgbe + "-Y 30000 +X 30000\n" + pixels, "truncated");
  expectError("huge.pfm", "PF\n40000 40000\n-1.0\n" + pixels, "truncated");
  // An EXR file's bytes with the int32 `skip` bytes after attribute `name` of `type` set to v.
  auto patchedExr = [&](const std::string& file, const std::string& name, const std::string& type, size_t skip,
                        int32_t v) {
    std::ifstream in(d / file, std::ios::binary);
    std::string exr((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    const std::string key = name + '\0' + type + '\0';
    const size_t at = exr.find(key);
    EXPECT_NE(at, std::string::npos) << name;
    if (at != std::string::npos) std::memcpy(&exr[at + key.size() + skip], &v, 4);
    return exr;
  };
  {
    // An EXR whose dataWindow says 10 M x 2 pixels over a few hundred bytes (its offset table,
    // one chunk, is whole): refused before its 240 MB are allocated.
    Image small(4, 2);
    saveImage(small, (d / "small.exr").string());
    expectError("huge.exr", patchedExr("small.exr", "dataWindow", "box2i", 4 + 8, 9999999), "more than its");  // xMax
    expectError("inverted.exr", patchedExr("small.exr", "dataWindow", "box2i", 4 + 8, -7), "Invalid data window");  // xMax < xMin
  }
  {
    // A string attribute whose size field says 1.98 GB (a fuzz input's): refused from the
    // header, where OpenEXR's InputFile allocated it and read to the end (21 s, 1.9 GB).
    Imf::Header header(4, 2);
    header.insert("generatedBy", Imf::StringAttribute("envgi's test"));
    header.channels().insert("Y", Imf::Channel(Imf::FLOAT));
    std::vector<float> grey(8, 0.5f);
    Imf::FrameBuffer fb;
    fb.insert("Y", Imf::Slice(Imf::FLOAT, reinterpret_cast<char*>(grey.data()), sizeof(float), 4 * sizeof(float)));
    {
      Imf::OutputFile out((d / "attr.exr").string().c_str(), header);
      out.setFrameBuffer(fb);
      out.writePixels(2);
    }
    expectError("huge-attribute.exr", patchedExr("attr.exr", "generatedBy", "string", 0, 0x76000015), "generatedBy");
  }

  // A PNG whose second chunk claims 4 GB, and a JPEG cut inside its data.
  Image img(64, 32);
  for (size_t i = 0; i < img.rgb.size(); ++i) img.rgb[i] = float(i % 13) / 13.f;
  saveImage(img, (d / "full.png").string());
  saveImage(img, (d / "full.jpg").string());
  std::string png, jpg;
  {
    std::ifstream a(d / "full.png", std::ios::binary), b(d / "full.jpg", std::ios::binary);
    png.assign(std::istreambuf_iterator<char>(a), {});
    jpg.assign(std::istreambuf_iterator<char>(b), {});
  }
  // PNG signature (8) and IHDR (4 + 4 + 13 + 4): the next chunk's length follows.
  png.replace(33, 4, "\xff\xff\xff\xf0");
  png[37] = 't';  // an ancillary chunk type, which a reader skips
  expectError("long-chunk.png", png, "cannot read image");
  expectError("cut.jpg", jpg.substr(0, jpg.size() / 2), "cannot read image");
  fs::remove_all(d);
}

TEST(Image, FailedWriteLeavesNoFile) {
  fs::path d = tmpDir();
  EXPECT_THROW(saveImage(pattern(), (d / "missing_dir" / "x.exr").string()), std::runtime_error);
  EXPECT_THROW(saveImage(pattern(), (d / "x.unknownext").string()), std::runtime_error);
  EXPECT_FALSE(fs::exists(d / "x.unknownext"));
  size_t n = 0;
  for (auto& e : fs::directory_iterator(d)) { (void)e; ++n; }
  EXPECT_EQ(n, 0u) << "no temporary files left behind";
  fs::remove_all(d);
}

// Channels beside R, G, B (AOVs) go into an .exr and come back by name; the other formats write
// the RGB alone; a channel of the wrong size or named twice is an error and leaves no file.
TEST(Image, ExrKeepsFurtherChannels) {
  fs::path d = tmpDir();
  Image img = pattern();
  std::vector<float> depth(15), nx(15);
  for (int i = 0; i < 15; ++i) depth[size_t(i)] = 0.25f * float(i), nx[size_t(i)] = -float(i);
  img.channels = {{"dd.T", depth}, {"nn.X", nx}};
  std::string p = (d / "aov.exr").string();
  saveImage(img, p);
  Image back = loadImage(p);
  EXPECT_EQ(back.rgb, img.rgb);
  ASSERT_EQ(back.channels.size(), 2u);
  for (const ImageChannel& c : back.channels) EXPECT_EQ(c.values, c.name == "dd.T" ? depth : nx) << c.name;
  saveImage(img, (d / "aov.pfm").string());
  EXPECT_TRUE(loadImage((d / "aov.pfm").string()).channels.empty());
  EXPECT_TRUE(loadImage((d / "aov.pfm").string()).rgb == img.rgb);
  Image bad = pattern();
  bad.channels = {{"short", std::vector<float>(3, 0.f)}};
  EXPECT_THROW(saveImage(bad, (d / "bad.exr").string()), std::runtime_error);
  bad.channels = {{"R", depth}};
  EXPECT_THROW(saveImage(bad, (d / "bad.exr").string()), std::runtime_error);
  EXPECT_FALSE(fs::exists(d / "bad.exr"));
  fs::remove_all(d);
}

// A channel named A makes a .png RGBA: its alpha is the channel, clamped to [0, 1], not tone
// mapped; without it the PNG is RGB.
TEST(Image, PngTakesTheAChannelAsAlpha) {
  fs::path d = tmpDir();
  Image img = pattern();
  std::vector<float> a(15);
  for (int i = 0; i < 15; ++i) a[size_t(i)] = float(i) / 10.f - 0.2f;  // -0.2 .. 1.2
  a[5] = 0.2f;
  img.channels = {{"A", a}};
  saveImage(img, (d / "a.png").string());
  int w = 0, h = 0, n = 0;
  unsigned char* px = stbi_load((d / "a.png").string().c_str(), &w, &h, &n, 0);
  ASSERT_NE(px, nullptr);
  EXPECT_EQ(n, 4);
  EXPECT_EQ(px[3], 0) << "-0.2 clamps to 0";
  EXPECT_EQ(px[4 * 5 + 3], 51) << "0.2 of 255";
  EXPECT_EQ(px[4 * 14 + 3], 255) << "1.2 clamps to 1";
  stbi_image_free(px);
  img.channels.clear();
  saveImage(img, (d / "b.png").string());
  px = stbi_load((d / "b.png").string().c_str(), &w, &h, &n, 0);
  ASSERT_NE(px, nullptr);
  EXPECT_EQ(n, 3);
  stbi_image_free(px);
  fs::remove_all(d);
}

// OpenEXR's worker threads (setImageThreads; render's --threads) compress a file's blocks in
// parallel: the same bytes on disk and the same pixels read back whatever their count, on an
// image of many ZIP blocks (16 scanlines each) with an AOV channel.
TEST(Image, ExrFilesAreTheSameWhateverTheThreads) {
  fs::path d = tmpDir();
  Image img(300, 200);
  std::mt19937 rng(5);
  std::uniform_real_distribution<float> u(0.f, 4.f);
  for (int y = 0; y < img.height; ++y)
    for (int x = 0; x < img.width; ++x) img.set(x, y, Color(u(rng), u(rng), u(rng)));
  img.channels.push_back({"depth.T", std::vector<float>(size_t(img.width) * img.height, 2.5f)});
  auto bytes = [](const fs::path& p) {
    std::ifstream f(p, std::ios::binary);
    return std::string(std::istreambuf_iterator<char>(f), {});
  };
  std::string first;
  for (int threads : {1, 2, 7, 0}) {
    setImageThreads(threads);
    const fs::path p = d / ("t" + std::to_string(threads) + ".exr");
    saveImage(img, p.string());
    if (first.empty()) first = bytes(p);
    EXPECT_EQ(bytes(p), first) << threads << " threads";
    Image back = loadImage(p.string());
    ASSERT_EQ(back.width, 300);
    EXPECT_EQ(back.rgb, img.rgb) << threads << " threads";
  }
  setImageThreads(0);
  fs::remove_all(d);
}
