// `envgi envmap info|samples|plot`: look at a map and at what each strategy draws from it.
#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include <algorithm>
#include <memory>
#include <stdexcept>

#include "cli/Commands.h"
#include "core/Files.h"
#include "envmap/EnvironmentMap.h"
#include "envmap/LightProbe.h"
#include "image/Image.h"
#include "sampling/Sampler.h"
#include "scene/NameTables.h"

namespace envgi::cli {

int parseStrategyName(const std::string& name) { return int(findStrategy(name, true).env); }


namespace {

struct SampleArgs {
  std::string map, out, strategy = "importance", sampler = "independent", layout = "latlong";
  int count = 1000;
  std::vector<float> normal{0.f, 1.f, 0.f};  // cosine and product sample about it (map frame)
  uint32_t seed = 0;
  bool misCompensation = false;
};

// --layout: what the map and the statistics are of when the file is a light probe.
void addLayoutOption(CLI::App* c, std::string& layout) {
  c->add_option("--layout", layout, "latlong (the default), or a light probe resampled first: angular, mirrorball, cross")
      ->check(CLI::IsMember({"latlong", "angular", "mirrorball", "cross"}));
}

std::vector<EnvSample> drawSamples(const EnvironmentMap& env, const SampleArgs& a) {
  if (a.count <= 0) throw std::runtime_error("--count must be positive");
  EnvStrategy s = EnvStrategy(parseStrategyName(a.strategy));
  Vec3f n(a.normal[0], a.normal[1], a.normal[2]);
  if (!(lengthSq(n) > 0.f) || !isFiniteVec(n)) throw std::runtime_error("--normal must be a non-zero direction x,y,z");
  EnvironmentMapView v = env.view();
  n = v.fromLocal(normalize(n));
  Sampler smp;
  smp.type = findSampler(a.sampler);
  smp.spp = uint32_t(a.count);
  smp.seed = a.seed;
  std::vector<EnvSample> out(a.count);
  for (int i = 0; i < a.count; ++i) {
    smp.start(0, uint32_t(i));
    out[i] = v.sample(s, smp.get2D(), n);
  }
  return out;
}

void addSampleOptions(CLI::App* c, SampleArgs& a) {
  c->add_option("map", a.map, "Lat-long map (.hdr, .exr, .pfm)")->required();
  addLayoutOption(c, a.layout);
  // The samples are held (and `samples` writes its CSV, ~80 bytes a sample) in memory: 2^24 of
  // them is a 1.3 GB file, and two billion had ended in std::bad_alloc.
  c->add_option("--count,-n", a.count, "Number of samples")->check(wholeNumberFrom(1, 1 << 24));
  c->add_option("--strategy,-s", a.strategy, strategyNameList(true) + " (cosine and product about --normal)");
  c->add_option("--normal", a.normal, "x,y,z: the surface normal, in the map's frame, for cosine and product (default 0,1,0)")
      ->expected(3)
      ->delimiter(',');
  c->add_option("--sampler", a.sampler, nameList(kSamplerNames));
  c->add_option("--seed", a.seed, "Seed")->check(atLeast(0));
  c->add_flag("--mis-compensation", a.misCompensation, "Sample max(L - mean, 0) (Karlik et al. 2019)");
}

EnvironmentMapOptions mapOptions(const SampleArgs& a) {
  EnvironmentMapOptions o;
  o.misCompensation = a.misCompensation;
  return o;
}

void runInfo(const std::string& path, const std::string& layout) {
  EnvironmentMap env = EnvironmentMap::loadLayout(path, layout);
  EnvironmentMapStats s = env.stats();
  fmt::print("map:            {}\n", path);
  fmt::print("size:           {} x {}\n", s.width, s.height);
  fmt::print("channel min:    {:.6g} {:.6g} {:.6g}\n", s.channelMin.x, s.channelMin.y, s.channelMin.z);
  fmt::print("channel max:    {:.6g} {:.6g} {:.6g}\n", s.channelMax.x, s.channelMax.y, s.channelMax.z);
  fmt::print("power (RGB):    {:.6g} {:.6g} {:.6g}   (integral of L over the sphere)\n", s.power.x, s.power.y, s.power.z);
  fmt::print("power (Y):      {:.6g}\n", env.luminancePower());
  fmt::print("luminance:      min {:.6g}  max {:.6g}  median {:.6g}  mean (solid angle) {:.6g}\n", s.lumMin, s.lumMax,
             s.lumMedian, s.lumMeanSolidAngle);
  fmt::print("brightest 1%:   {:.2f}% of the energy\n", 100.f * s.top1PercentEnergy);
  fmt::print("invalid values: {}\n", s.invalidPixels);
}

void runSamples(const SampleArgs& a) {
  // A CSV in a file named as an image is a slip (any other name is the user's choice).
  const std::string ext = lowerExtension(a.out);
  for (const char* image : {".png", ".jpg", ".jpeg", ".exr", ".hdr", ".pfm", ".tif", ".tiff", ".bmp"})
    if (ext == image)
      throw std::runtime_error(fmt::format("output '{}' names an image, but samples writes CSV (u,v,x,y,z,pdf): name it .csv",
                                           a.out));
  requireWritableDirectoryOf(a.out);
  EnvironmentMap env = EnvironmentMap::loadLayout(a.map, a.layout, mapOptions(a));
  std::vector<EnvSample> samples = drawSamples(env, a);
  std::string csv = "u,v,x,y,z,pdf\n";
  csv.reserve(samples.size() * 80);
  EnvironmentMapView v = env.view();
  for (const EnvSample& s : samples) {
    Vec3f d = v.toLocal(s.dir);
    csv += fmt::format("{:.7g},{:.7g},{:.7g},{:.7g},{:.7g},{:.7g}\n", s.uv.x, s.uv.y, d.x, d.y, d.z, s.pdf);
  }
  writeFileAtomically(a.out, csv);
  spdlog::info("wrote {} {} samples to {}", samples.size(), a.strategy, a.out);
}

void runPlot(const SampleArgs& a, float exposure) {
  requireOutputExtension(a.out, imageWriterExtensions(), "output");
  EnvironmentMap env = EnvironmentMap::loadLayout(a.map, a.layout, mapOptions(a));
  std::vector<EnvSample> samples = drawSamples(env, a);
  Image img = env.image();
  SaveOptions so;
  if (std::isnan(exposure)) {
    // Auto exposure: the 97th percentile of luminance lands at 0.8, so windows and suns saturate
    // but the rest of the map stays readable.
    std::vector<float> lum(size_t(img.width) * img.height);
    for (size_t i = 0; i < lum.size(); ++i) lum[i] = luminance(img.rgb[i * 3], img.rgb[i * 3 + 1], img.rgb[i * 3 + 2]);
    size_t k = lum.size() * 97 / 100;
    std::nth_element(lum.begin(), lum.begin() + k, lum.end());
    so.exposure = lum[k] > 0.f ? std::log2(0.8f / lum[k]) : 0.f;
  } else {
    so.exposure = exposure;
  }
  // Dots as in the paper's Figure 2: a dark ring around a bright centre; colours are written
  // after tone mapping, so they are set to values that survive it (1/exposure scaled).
  float inv = std::exp2(-so.exposure);
  int rOuter = std::max(1, img.width / 512 + 1), rInner = std::max(0, rOuter - 1);
  for (const EnvSample& s : samples) {
    int cx = std::clamp(int(s.uv.x * img.width), 0, img.width - 1);
    int cy = std::clamp(int(s.uv.y * img.height), 0, img.height - 1);
    for (int dy = -rOuter; dy <= rOuter; ++dy)
      for (int dx = -rOuter; dx <= rOuter; ++dx) {
        int x = (cx + dx + img.width) % img.width, y = cy + dy;
        if (y < 0 || y >= img.height) continue;
        bool inner = std::abs(dx) <= rInner && std::abs(dy) <= rInner;
        img.set(x, y, inner ? Color(inv, 0.f, 0.f) : Color(0.f));
      }
  }
  saveImage(img, a.out, so);
  spdlog::info("wrote {} with {} {} samples", a.out, samples.size(), a.strategy);
}

struct ConvertArgs {
  std::string probe, out, layout = "angular";
  int width = 0, samples = 0;
};

void runConvert(const ConvertArgs& a) {
  ProbeLayout layout = parseProbeLayout(a.layout);
  // A map to light scenes with keeps its HDR values: not tone-mapped into a .png or .jpg.
  requireOutputExtension(a.out, {".exr", ".hdr", ".pfm"}, "output");
  Image probe = loadImage(a.probe);
  ProbeConversion c;
  c.width = a.width;
  c.samplesPerSide = a.samples;
  size_t invalid = 0;
  Image map = probeToLatLong(probe, layout, c, &invalid);
  if (invalid > 0) spdlog::warn("{}: {} NaN, infinite or negative channel values read as 0", a.probe, invalid);
  saveImage(map, a.out);
  spdlog::info("wrote {} ({}x{} lat-long) from the {} {} ({}x{})", a.out, map.width, map.height, a.layout, a.probe,
               probe.width, probe.height);
}

}  // namespace

void addEnvmapCommands(CLI::App& app) {
  CLI::App* env = app.add_subcommand("envmap", "Inspect and sample environment maps");
  env->require_subcommand(1);

  auto path = std::make_shared<std::string>(), layout = std::make_shared<std::string>("latlong");
  CLI::App* info = env->add_subcommand("info", "Size, channel ranges, power and luminance statistics");
  info->add_option("map", *path, "Lat-long map")->required();
  addLayoutOption(info, *layout);
  info->callback([path, layout] { runInfo(*path, *layout); });

  auto sa = std::make_shared<SampleArgs>();
  CLI::App* samples = env->add_subcommand("samples", "Write samples as CSV: u,v,x,y,z,pdf (map frame, solid angle)");
  addSampleOptions(samples, *sa);
  samples->add_option("-o,--output", sa->out, "CSV file (any name but an image's)")->required();
  samples->callback([sa] { runSamples(*sa); });

  auto pa = std::make_shared<SampleArgs>();
  auto exposure = std::make_shared<float>(NAN);
  CLI::App* plot = env->add_subcommand("plot", "The paper's Figure 2: the map with its samples drawn on it");
  addSampleOptions(plot, *pa);
  plot->add_option("-o,--output", pa->out, "Image (.png, .jpg, .exr, .hdr, .pfm)")->required();
  plot->add_option("--exposure", *exposure, "Exposure in stops (default: automatic)")->check(finiteNumber());
  plot->callback([pa, exposure] { runPlot(*pa, *exposure); });

  auto ca = std::make_shared<ConvertArgs>();
  CLI::App* convert = env->add_subcommand(
      "convert", "Resample a light probe (angular map, mirror ball, cube cross) to a lat-long map, forward in its centre column");
  convert->add_option("probe", ca->probe, "Probe image (.hdr, .exr, .pfm)")->required();
  convert->add_option("-o,--output", ca->out, "Lat-long map (.exr, .hdr, .pfm)")->required();
  convert->add_option("--layout", ca->layout,
                      "angular (Debevec's gallery; the default), mirrorball, or cross (a cube cross, 3N x 4N or 4N x 3N)");
  convert->add_option("--width", ca->width, "Map width, even (default: twice a disk's width, four times a cube face's)")
      ->check(atLeast(2));
  convert->add_option("--samples", ca->samples, "n: n x n lookups a map pixel (default: enough for the probe's detail)")
      ->check(atLeast(1));
  convert->callback([ca] { runConvert(*ca); });
}

}  // namespace envgi::cli
