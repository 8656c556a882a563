// `envgi image info|convert|diff`: what pbrt's imgtool does every day, on envgi's formats. info
// gives an image's size, channels, range, means and bad values; convert writes it in another
// format (8-bit outputs tone-mapped, with exposure); diff draws a false-colour map of one
// image's relative error (or its FLIP error) against another and prints compare's figures and
// the mean FLIP for it.
#include <fmt/format.h>

#include <cmath>
#include <limits>
#include <memory>

#include "cli/Commands.h"
#include "core/Files.h"
#include "image/FalseColour.h"
#include "image/Image.h"
#include "study/ErrorMetrics.h"
#include "study/FlipError.h"

namespace envgi::cli {

namespace {

struct ImageArgs {
  std::string input, output, reference;
  float exposure = 0.f;
  bool aces = false;
  std::string metric = "relative";  // diff's picture: relative or flip
};

void runInfo(const ImageArgs& a) {
  const Image img = loadImage(a.input);
  double sum[3] = {0, 0, 0}, lum = 0.0;
  float lo[3], hi[3];
  for (int k = 0; k < 3; ++k) lo[k] = std::numeric_limits<float>::infinity(), hi[k] = -lo[k];
  size_t nan = 0, inf = 0, negative = 0, finitePixels = 0;
  for (int y = 0; y < img.height; ++y)
    for (int x = 0; x < img.width; ++x) {
      const Color c = img.at(x, y);
      bool finite = true;
      for (int k = 0; k < 3; ++k) {
        const float v = c[k];
        nan += std::isnan(v);
        inf += std::isinf(v);
        negative += v < 0.f;
        finite = finite && std::isfinite(v);
        if (!std::isfinite(v)) continue;
        lo[k] = std::min(lo[k], v), hi[k] = std::max(hi[k], v);
      }
      if (!finite) continue;
      for (int k = 0; k < 3; ++k) sum[k] += c[k];
      lum += luminance(c);
      ++finitePixels;
    }
  const double n = std::max<double>(1.0, double(finitePixels));
  fmt::print("image:          {}\n", a.input);
  fmt::print("size:           {} x {}\n", img.width, img.height);
  std::string channels = "R, G, B";
  for (const ImageChannel& c : img.channels) channels += ", " + c.name;
  fmt::print("channels:       {}\n", channels);
  fmt::print("mean (RGB):     {:.6g} {:.6g} {:.6g}\n", sum[0] / n, sum[1] / n, sum[2] / n);
  fmt::print("mean luminance: {:.6g}\n", lum / n);
  fmt::print("min (RGB):      {:.6g} {:.6g} {:.6g}\n", lo[0], lo[1], lo[2]);
  fmt::print("max (RGB):      {:.6g} {:.6g} {:.6g}\n", hi[0], hi[1], hi[2]);
  fmt::print("NaN values:     {}\ninfinite:       {}\nnegative:       {}\n", nan, inf, negative);
  if (nan + inf > 0) fmt::print("(means, min and max are over the {} pixels whose values are all finite)\n", finitePixels);
}

void runConvert(const ImageArgs& a) {
  const Image img = loadImage(a.input);
  SaveOptions so;
  so.exposure = a.exposure;
  so.toneMap = a.aces ? ToneMap::Aces : ToneMap::Clamp;
  saveImage(img, a.output, so);
  fmt::print("wrote {} ({} x {}) from {}\n", a.output, img.width, img.height, a.input);
}

void runDiff(const ImageArgs& a) {
  requireOutputExtension(a.output, {".png"}, "diff picture");
  const Image img = loadImage(a.input), ref = loadImage(a.reference);
  const ImageError e = imageError(img, ref);  // throws, naming both sizes, where they differ
  // HDR-FLIP: envgi's images are linear radiance of any range.
  const std::vector<float> flip = flipHdr(ref, img);
  // The ramp's own codes, with no tone curve.
  const std::vector<unsigned char> picture = a.metric == "flip" ? rampRgb(flip) : errorMapRgb(img, ref);
  writeFileAtomically(a.output, encodePng(img.width, img.height, picture));
  fmt::print("RMSE {:.6g}, relMSE {:.6g}, worst region {:.6g}, HDR-FLIP mean {:.6g}, non-finite {}\n", e.rmse, e.relMse,
             e.worstRegionRmse, flipMean(flip), nonFiniteValues(img));
  if (a.metric == "flip")
    fmt::print("wrote {}: HDR-FLIP (NVIDIA's, at 67 pixels a degree), 0 (dark blue) to 1 (red)\n", a.output);
  else
    fmt::print("wrote {}: |L - L_ref| / (L_ref + 0.05), 0 (dark blue) to 1 or more (red)\n", a.output);
}

}  // namespace

void addImageCommands(CLI::App& app) {
  CLI::App* img = app.add_subcommand("image", "Image tools: info, convert, diff");
  img->require_subcommand(1);
  auto a = std::make_shared<ImageArgs>();
  CLI::App* info = img->add_subcommand("info", "Size, channels, means, range and NaN / infinite / negative counts");
  info->add_option("image", a->input, "Image (.exr, .pfm, .hdr, .png, .jpg)")->required()->check(CLI::ExistingFile);
  info->callback([a] { runInfo(*a); });
  CLI::App* convert = img->add_subcommand("convert", "Write an image in another format (8-bit ones tone-mapped)");
  convert->add_option("image", a->input, "Input image")->required()->check(CLI::ExistingFile);
  convert->add_option("-o,--output", a->output, "Output (.exr, .pfm, .hdr, .png, .jpg)")->required();
  convert->add_option("--exposure", a->exposure, "Stops, before the tone curve (8-bit outputs)");
  convert->add_flag("--aces", a->aces, "ACES filmic tone curve instead of a clamp (8-bit outputs)");
  convert->callback([a] { runConvert(*a); });
  CLI::App* diff = img->add_subcommand("diff", "A false-colour picture of an image's relative error against a reference");
  diff->add_option("reference", a->reference, "Reference image")->required()->check(CLI::ExistingFile);
  diff->add_option("image", a->input, "Image")->required()->check(CLI::ExistingFile);
  diff->add_option("-o,--output", a->output, "The picture (.png)")->required();
  diff->add_option("--metric", a->metric, "The picture's error: relative (default) or flip (HDR-FLIP)")
      ->check(CLI::IsMember({"relative", "flip"}));
  diff->callback([a] { runDiff(*a); });
}

}  // namespace envgi::cli
