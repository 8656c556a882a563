// `envgi compare REF IMAGE...`: each image's error against a reference (RMSE, relMSE and the
// worst of a 4x4 grid of regions, as the study measures it) and its mean, one row an image.
#include <fmt/format.h>

#include "cli/Commands.h"
#include "image/Image.h"
#include "study/ErrorMetrics.h"

namespace envgi::cli {

namespace {
struct CompareArgs {
  std::string reference;
  std::vector<std::string> images;
};

double meanOf(const Image& img) {
  double s = 0.0;
  for (float v : img.rgb) s += v;
  return img.rgb.empty() ? 0.0 : s / double(img.rgb.size());
}

void runCompare(const CompareArgs& a) {
  requireRadianceImage(a.reference, "compare");
  for (const std::string& path : a.images) requireRadianceImage(path, "compare");
  Image ref = loadImage(a.reference);
  if (size_t n = nonFiniteValues(ref))
    throw std::runtime_error(fmt::format("reference '{}' has {} NaN or infinite values", a.reference, n));
  // Every image read and checked before the table starts, so an error leaves no half table.
  struct Row {
    double mean;
    ImageError error;
    size_t nonFinite;
  };
  std::vector<Row> rows;
  for (const std::string& path : a.images) {
    Image img = loadImage(path);
    try {
      rows.push_back({meanOf(img), imageError(img, ref), nonFiniteValues(img)});
    } catch (const std::runtime_error& e) {
      throw std::runtime_error(path + ": " + e.what());
    }
  }
  // The last column counts NaN and infinite values: a render with any has every error NaN.
  fmt::print("{:<40} {:>10} {:>10} {:>10} {:>12} {:>10}\n", "image", "mean", "RMSE", "relMSE", "worst-region",
             "non-finite");
  fmt::print("{:<40} {:>10.5f} {:>10} {:>10} {:>12} {:>10}\n", a.reference + " (reference)", meanOf(ref), "-", "-", "-",
             0);
  for (size_t i = 0; i < rows.size(); ++i) {
    const ImageError& e = rows[i].error;
    fmt::print("{:<40} {:>10.5f} {:>10.5f} {:>10.5f} {:>12.5f} {:>10}\n", a.images[i], rows[i].mean, e.rmse, e.relMse,
               e.worstRegionRmse, rows[i].nonFinite);
  }
  // What the columns are, on stderr so that the table on stdout stays one row an image for scripts.
  fmt::print(stderr,
             "mean: of every pixel and channel; RMSE: over every pixel and channel; relMSE: the mean of (a - r)^2 / "
             "(r^2 + 0.01); worst-region: the largest RMSE of a 4 x 4 grid of regions (local error); non-finite: NaN "
             "or infinite values\n");
}
}  // namespace

void addCompareCommand(CLI::App& app) {
  auto a = std::make_shared<CompareArgs>();
  CLI::App* c = app.add_subcommand("compare", "Error of images against a reference (RMSE, relMSE, worst region)");
  c->add_option("reference", a->reference, "Reference image (.exr, .pfm, .hdr)")->required()->check(CLI::ExistingFile);
  c->add_option("images", a->images, "Images to compare (.exr, .pfm, .hdr), same size as the reference")->required()->check(CLI::ExistingFile);
  c->callback([a] { runCompare(*a); });
}

}  // namespace envgi::cli
