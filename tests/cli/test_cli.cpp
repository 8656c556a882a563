// End-to-end tests of the envgi command line: outputs, exit codes and error lines.
#include <fmt/format.h>
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "cli/CliRunner.h"
#include "envmap/LightProbe.h"
#include "image/Image.h"

using namespace envgi::test;
namespace fs = std::filesystem;

namespace {
std::string bundledMap() { return std::string(ENVGI_SOURCE_DIR) + "/scenes/envmaps/studio.hdr"; }

// The rows of a samples.csv (u, v, x, y, z, pdf), after checking its header and each row's form.
std::vector<std::array<float, 6>> readSamples(const std::string& path) {
  std::ifstream f(path);
  std::string line;
  std::getline(f, line);
  EXPECT_EQ(line, "u,v,x,y,z,pdf");
  std::vector<std::array<float, 6>> rows;
  while (std::getline(f, line)) {
    std::array<float, 6> r;
    EXPECT_EQ(std::sscanf(line.c_str(), "%f,%f,%f,%f,%f,%f", &r[0], &r[1], &r[2], &r[3], &r[4], &r[5]), 6) << line;
    rows.push_back(r);
  }
  return rows;
}
}  // namespace

TEST(CliEnvmap, InfoPrintsStatistics) {
  CliResult r = runCli("envmap info " + bundledMap());
  ASSERT_EQ(r.code, 0) << r.output;
  EXPECT_NE(r.output.find("size:           1024 x 512"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("brightest 1%"), std::string::npos);
}

TEST(CliEnvmap, SamplesCsvContract) {
  TempDir d;
  std::string out = d.file("s.csv");
  CliResult r = runCli("envmap samples " + bundledMap() + " --count 500 --strategy importance --seed 3 -o " + out);
  ASSERT_EQ(r.code, 0) << r.output;
  auto rows = readSamples(out);
  for (const auto& [u, v, x, y, z, pdf] : rows) {
    EXPECT_GE(u, 0.f);
    EXPECT_LT(u, 1.f);
    EXPECT_NEAR(x * x + y * y + z * z, 1.f, 1e-4f);
    EXPECT_GT(pdf, 0.f);
  }
  EXPECT_EQ(rows.size(), 500u);
  // Same seed, same file.
  std::string out2 = d.file("s2.csv");
  ASSERT_EQ(runCli("envmap samples " + bundledMap() + " --count 500 --strategy importance --seed 3 -o " + out2).code, 0);
  std::ifstream a(out), b(out2);
  std::stringstream sa, sb;
  sa << a.rdbuf();
  sb << b.rdbuf();
  EXPECT_EQ(sa.str(), sb.str());
}

// The product strategy about --normal: its samples stay above that normal's horizon, but for
// the bound's margin (the buckets and cells are a few degrees wide).
TEST(CliEnvmap, ProductSamplesAboutTheNormal) {
  TempDir d;
  std::string out = d.file("p.csv");
  CliResult r = runCli("envmap samples " + bundledMap() + " --count 2000 --strategy product --normal 0,-1,0 -o " + out);
  ASSERT_EQ(r.code, 0) << r.output;
  auto rows = readSamples(out);
  int below = 0;
  for (const auto& r : rows) {
    EXPECT_GT(r[5], 0.f);
    below += r[3] > 0.3f;  // y: more than 17 degrees on the wrong side of the horizon
  }
  EXPECT_EQ(rows.size(), 2000u);
  EXPECT_EQ(below, 0);
  CliResult zero = runCli("envmap samples " + bundledMap() + " --strategy product --normal 0,0,0 -o " + out + "2");
  EXPECT_NE(zero.code, 0);
  EXPECT_NE(zero.output.find("--normal must be a non-zero direction"), std::string::npos) << zero.output;
  EXPECT_FALSE(fs::exists(out + "2"));
  CliResult two = runCli("envmap samples " + bundledMap() + " --strategy product --normal 0,1 -o " + out + "2");
  EXPECT_NE(two.code, 0) << two.output;
  EXPECT_FALSE(fs::exists(out + "2"));
}

TEST(CliEnvmap, PlotWritesPng) {
  TempDir d;
  std::string out = d.file("fig2.png");
  CliResult r = runCli("envmap plot " + bundledMap() + " --count 300 -o " + out);
  ASSERT_EQ(r.code, 0) << r.output;
  EXPECT_GT(fs::file_size(out), 1000u);
}

TEST(CliEnvmap, ConvertMakesALatLongMapOfAProbe) {
  TempDir d;
  std::string probe = std::string(ENVGI_SOURCE_DIR) + "/scenes/envmaps/uffizi_probe_128.exr", out = d.file("uffizi.exr");
  CliResult r = runCli("envmap convert " + probe + " --width 64 -o " + out);
  ASSERT_EQ(r.code, 0) << r.output;
  EXPECT_NE(r.output.find("wrote " + out + " (64x32 lat-long) from the angular"), std::string::npos) << r.output;
  CliResult info = runCli("envmap info " + out);
  ASSERT_EQ(info.code, 0) << info.output;
  EXPECT_NE(info.output.find("size:           64 x 32"), std::string::npos) << info.output;
  // The other envmap commands read a probe as the scene does, through --layout.
  CliResult probeInfo = runCli("envmap info " + probe + " --layout angular");
  ASSERT_EQ(probeInfo.code, 0) << probeInfo.output;
  EXPECT_NE(probeInfo.output.find("size:           256 x 128"), std::string::npos) << probeInfo.output;
  // The probe's invalid values, replaced before it is resampled, are the ones info counts (it
  // had warned of 2764, then printed 0).
  EXPECT_NE(probeInfo.output.find("2764 NaN, infinite or negative channel values replaced"), std::string::npos)
      << probeInfo.output;
  EXPECT_NE(probeInfo.output.find("invalid values: 2764\n"), std::string::npos) << probeInfo.output;
  CliResult plot = runCli("envmap plot " + probe + " --layout mirrorball -n 50 -o " + d.file("p.png"));
  ASSERT_EQ(plot.code, 0) << plot.output;
  EXPECT_TRUE(fs::exists(d.file("p.png")));

  // A lat-long map given as a probe, an unknown layout, an odd width: one line each, no file.
  std::string never = d.file("never.exr");
  CliResult latlong = runCli("envmap convert " + bundledMap() + " -o " + never);
  EXPECT_NE(latlong.code, 0);
  EXPECT_NE(latlong.output.find("envgi: error: a light probe is a square image of at least 2x2, not 1024x512 (this looks"),
            std::string::npos)
      << latlong.output;
  CliResult layout = runCli("envmap convert " + probe + " --layout cubemap -o " + never);
  EXPECT_NE(layout.output.find("unknown light-probe layout 'cubemap' (angular, mirrorball, cross)"), std::string::npos)
      << layout.output;
  CliResult odd = runCli("envmap convert " + probe + " --width 33 -o " + never);
  EXPECT_NE(odd.output.find("must be even, from 2 to 32768, not 33"), std::string::npos) << odd.output;
  EXPECT_NE(layout.code, 0);
  EXPECT_NE(odd.code, 0);
  EXPECT_FALSE(fs::exists(never));
}

// Correlation of the luminance of a map made from a probe against the original map half a turn
// round (the probe's forward, the original's -Z, in the made map's centre column), its columns
// mirrored where asked, over rows [y0, y1) and the columns keep(x) keeps.
namespace {
template <class Keep>
double halfTurnCorrelation(const envgi::Image& made, const envgi::Image& orig, bool mirrored, int y0, int y1, Keep keep) {
  double sa = 0, sb = 0, saa = 0, sbb = 0, sab = 0, n = 0;
  int w = orig.width;
  for (int y = y0; y < y1; ++y)
    for (int x = 0; x < w; ++x) {
      if (!keep(x)) continue;
      int ox = (x + w / 2) % w;
      if (mirrored) ox = w - 1 - ox;
      double a = envgi::luminance(made.at(x, y)), b = envgi::luminance(orig.at(ox, y));
      sa += a, sb += b, saa += a * a, sbb += b * b, sab += a * b, n += 1;
    }
  return (sab - sa * sb / n) / std::sqrt((saa - sa * sa / n) * (sbb - sb * sb / n));
}
// The bundled Uffizi lat-long map, and a scene file in d lit by it alone: a square, box-filtered
// Sobol camera with the given field of view and lookat, and `body` (shapes, integrator) beside it.
std::string uffiziMap() { return std::string(ENVGI_SOURCE_DIR) + "/scenes/envmaps/uffizi_probe_128_latlong_256x128.hdr"; }
std::string writeUffiziScene(const TempDir& d, const std::string& name, const std::string& fov, const std::string& lookat,
                             int spp, int res, const std::string& body) {
  std::ofstream(d.file(name)) << R"(<scene version="3.0.0">
  <sensor type="perspective"><float name="fov" value=")" + fov + R"("/>
    <transform name="to_world"><lookat )" + lookat + R"(/></transform>
    <sampler type="sobol"><integer name="sample_count" value=")" + std::to_string(spp) + R"("/></sampler>
    <film type="hdrfilm"><integer name="width" value=")" + std::to_string(res) + R"("/><integer name="height" value=")" +
                                     std::to_string(res) + R"("/><rfilter type="box"/></film>
  </sensor>
  <emitter type="envmap"><string name="filename" value=")" + uffiziMap() + R"("/></emitter>
  )" + body + R"(
</scene>)";
  return d.file(name);
}
}  // namespace

// The mirror-ball layout against physics: envgi renders a chrome sphere in a lat-long map,
// seen from far down -Z looking along +Z (nearly orthographic, the ball filling the frame); that picture,
// converted as a mirror ball, must give the map back. The converted map faces the ball's centre,
// -Z, in its centre column, where the original has +Z: half a turn apart. Mirrored left and
// right it would not match.
TEST(CliEnvmap, AChromeSpheresPictureConvertsBackToItsMap) {
  TempDir d;
  std::string map = uffiziMap();
  writeUffiziScene(d, "ball.xml", "0.11459", R"(origin="0,0,-1000" target="0,0,0" up="0,1,0")", 16, 128,
                   R"(<integrator type="path"><integer name="max_depth" value="2"/></integrator>
  <shape type="sphere"><float name="radius" value="1"/><bsdf type="conductor"/></shape>)");
  CliResult r = runCli("render " + d.file("ball.xml") + " -o " + d.file("ball.exr") + " --no-progress");
  ASSERT_EQ(r.code, 0) << r.output;
  CliResult c = runCli("envmap convert " + d.file("ball.exr") + " --layout mirrorball --width 256 -o " + d.file("back.exr"));
  ASSERT_EQ(c.code, 0) << c.output;
  envgi::Image orig = envgi::loadImage(map), back = envgi::loadImage(d.file("back.exr"));
  ASSERT_EQ(back.width, orig.width);
  ASSERT_EQ(back.height, orig.height);
  // Correlation over the hemisphere that faces the camera (the ball's rim squeezes the other),
  // away from the poles; `mirrored` reads the original with its columns reversed.
  auto correlation = [&](bool mirrored) {
    return halfTurnCorrelation(back, orig, mirrored, 20, 108, [](int x) { return x >= 64 && x < 192; });
  };
  EXPECT_GT(correlation(false), 0.995);
  EXPECT_LT(correlation(true), 0.99);
}

// The cube crosses against envgi's own camera: six 90-degree views from the centre of a map,
// rendered by envgi and laid out as a vertical cross (the backward view upside down) and as a
// horizontal one, convert back to the map, half a turn round as for the mirror ball.
TEST(CliEnvmap, CrossesOfRenderedCubeFacesConvertBackToTheirMap) {
  TempDir d;
  std::string map = uffiziMap();
  writeUffiziScene(d, "face.xml", "90", R"(origin="0,0,0" target="$target" up="$up")", 4, 32, "");
  // Faces +X, -X, +Y, -Y, +Z (upside down, then upright), -Z: where each looks and its up.
  const char* views[7][2] = {{"1,0,0", "0,1,0"},  {"-1,0,0", "0,1,0"}, {"0,1,0", "0,0,1"}, {"0,-1,0", "0,0,-1"},
                             {"0,0,1", "0,-1,0"}, {"0,0,1", "0,1,0"},  {"0,0,-1", "0,1,0"}};
  std::vector<envgi::Image> faces;
  for (int i = 0; i < 7; ++i) {
    std::string out = d.file("f" + std::to_string(i) + ".exr");
    CliResult r = runCli("render " + d.file("face.xml") + " -o " + out + " --no-progress -D target=" + views[i][0] +
                         " -D up=" + views[i][1]);
    ASSERT_EQ(r.code, 0) << r.output;
    faces.push_back(envgi::loadImage(out));
  }
  envgi::Image orig = envgi::loadImage(map);
  for (bool vertical : {true, false}) {
    envgi::Image cross(vertical ? 96 : 128, vertical ? 128 : 96);
    for (int f = 0; f < 6; ++f) {
      int col, row;
      envgi::crossCell(f, vertical, &col, &row);
      const envgi::Image& view = faces[f < 4 ? f : (f == 4 ? (vertical ? 4 : 5) : 6)];
      for (int y = 0; y < 32; ++y)
        for (int x = 0; x < 32; ++x) cross.set(col * 32 + x, row * 32 + y, view.at(x, y));
    }
    std::string crossFile = d.file(vertical ? "vcross.exr" : "hcross.exr"), back = d.file("back.exr");
    envgi::saveImage(cross, crossFile);
    CliResult c = runCli("envmap convert " + crossFile + " --layout cross --width 256 -o " + back);
    ASSERT_EQ(c.code, 0) << c.output;
    envgi::Image conv = envgi::loadImage(back);
    // Over the whole map away from the poles, or over the middle of the backward face alone
    // (the converted map's seam), which the vertical cross holds upside down.
    auto correlation = [&](bool mirrored, bool backOnly = false) {
      if (backOnly) return halfTurnCorrelation(conv, orig, mirrored, 40, 88, [](int x) { return x < 24 || x >= 232; });
      return halfTurnCorrelation(conv, orig, mirrored, 8, 120, [](int) { return true; });
    };
    EXPECT_GT(correlation(false), 0.99) << (vertical ? "vertical" : "horizontal");
    EXPECT_LT(correlation(true), 0.97) << (vertical ? "vertical" : "horizontal");
    EXPECT_GT(correlation(false, true), 0.95) << (vertical ? "vertical" : "horizontal") << ", backward face";
  }
}

TEST(CliEnvmap, ErrorsAreOneLineAndLeaveNoFile) {
  TempDir d;
  std::string out = d.file("never.csv");
  CliResult missing = runCli("envmap samples /nonexistent/map.hdr --count 5 -o " + out);
  EXPECT_NE(missing.code, 0);
  EXPECT_NE(missing.output.find("envgi: error: cannot open image"), std::string::npos) << missing.output;
  EXPECT_FALSE(fs::exists(out));

  std::string bad = d.file("bad.hdr");
  { std::ofstream f(bad); f << "#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n-Y 512 +X 1024\n\x02\x02"; }
  CliResult trunc = runCli("envmap info " + bad);
  EXPECT_NE(trunc.code, 0);
  EXPECT_NE(trunc.output.find("envgi: error:"), std::string::npos) << trunc.output;

  CliResult strat = runCli("envmap samples " + bundledMap() + " --strategy bogus -o " + out);
  EXPECT_NE(strat.code, 0);
  EXPECT_NE(strat.output.find("unknown strategy 'bogus'"), std::string::npos) << strat.output;
  EXPECT_FALSE(fs::exists(out));

  CliResult count = runCli("envmap samples " + bundledMap() + " --count -4 -o " + out);
  EXPECT_NE(count.code, 0);
  EXPECT_FALSE(fs::exists(out));
}

// An output whose name says another kind of file is refused before any work: samples' CSV in a
// file named as an image, a plot in a format envgi does not write, and a converted map in a
// tone-mapped .png or .jpg, which would lose the HDR values that light a scene (it was written).
TEST(CliEnvmap, AnOutputNamedAsTheWrongKindOfFileIsRefused) {
  TempDir d;
  const std::string probe = std::string(ENVGI_SOURCE_DIR) + "/scenes/envmaps/uffizi_probe_128.exr";
  struct Case {
    std::string args, file, message;
  };
  const Case cases[] = {
      {"envmap samples " + bundledMap() + " --count 5", "s.png", "names an image, but samples writes CSV"},
      {"envmap plot " + bundledMap() + " --count 5", "p.tif", "must end in .exr, .pfm, .hdr, .png, .jpg or .jpeg"},
      {"envmap samples " + bundledMap() + " --count 5", "s.PNG", "names an image, but samples writes CSV"},
      {"envmap convert " + probe + " --width 64", "c.jpg", "must end in .exr, .hdr or .pfm"},
      {"envmap convert " + probe + " --width 64", "c.png", "must end in .exr, .hdr or .pfm"},
  };
  for (const Case& c : cases) {
    CliResult r = runCli(c.args + " -o " + d.file(c.file));
    EXPECT_EQ(r.code, 1) << c.args << ": " << r.output;
    const std::string expected = fmt::format("envgi: error: output '{}' {}", d.file(c.file), c.message);
    EXPECT_NE(r.output.find(expected), std::string::npos) << r.output;
    EXPECT_FALSE(fs::exists(d.file(c.file))) << c.file;
  }
  // What they do write: a CSV under a name without .csv, a plot as .exr or .JPEG, a map as .hdr
  // or .EXR (extensions in any case, as saveImage reads them).
  for (const std::string& ok : {"envmap samples " + bundledMap() + " --count 5 -o " + d.file("s"),
                                "envmap plot " + bundledMap() + " --count 5 -o " + d.file("p.exr"),
                                "envmap plot " + bundledMap() + " --count 5 -o " + d.file("p.JPEG"),
                                "envmap convert " + probe + " --width 64 -o " + d.file("c.hdr"),
                                "envmap convert " + probe + " --width 64 -o " + d.file("c.EXR")}) {
    CliResult r = runCli(ok);
    EXPECT_EQ(r.code, 0) << ok << ": " << r.output;
  }
}

// `envgi image`: info counts what compare once had to be run to see (means, range, NaN and
// infinite values), convert writes another format with exposure, diff draws the relative error
// in the study's colours and prints compare's figures.
TEST(CliImage, InfoConvertAndDiff) {
  TempDir d;
  envgi::Image img(4, 2);
  for (int x = 0; x < 4; ++x) img.set(x, 0, envgi::Color(0.25f * float(x)));
  img.set(0, 1, envgi::Color(0.5f));
  img.rgb[3 * 5] = NAN;  // pixel (1, 1)'s red
  img.rgb[3 * 6 + 1] = INFINITY;
  envgi::saveImage(img, d.file("a.pfm"));
  CliResult info = runCli("image info " + d.file("a.pfm"));
  ASSERT_EQ(info.code, 0) << info.output;
  EXPECT_NE(info.output.find("size:           4 x 2"), std::string::npos) << info.output;
  EXPECT_NE(info.output.find("NaN values:     1\ninfinite:       1\n"), std::string::npos) << info.output;
  // The six all-finite pixels: 0, 0.25, 0.5, 0.75, 0.5 and two zeros.
  EXPECT_NE(info.output.find(fmt::format("mean (RGB):     {:.6g}", 2.0 / 6.0)), std::string::npos) << info.output;
  EXPECT_NE(info.output.find("max (RGB):      0.75 0.75 0.75"), std::string::npos) << info.output;

  envgi::Image grey(2, 2);
  for (float& v : grey.rgb) v = 0.25f;
  envgi::saveImage(grey, d.file("grey.exr"));
  CliResult convert = runCli("image convert " + d.file("grey.exr") + " -o " + d.file("grey.png") + " --exposure 2");
  ASSERT_EQ(convert.code, 0) << convert.output;
  const envgi::Image png = envgi::loadImage(d.file("grey.png"));
  EXPECT_NEAR(png.at(0, 0).x, 1.0f, 0.01f) << "0.25 at +2 stops is 1";
  EXPECT_NE(runCli("image convert " + d.file("grey.exr") + " -o " + d.file("grey.txt")).code, 0);

  // Against itself the picture is dark blue (the ramp at 0) and the RMSE 0; against a brighter
  // copy it is red where the error is 1 or more.
  CliResult same = runCli("image diff " + d.file("grey.exr") + " " + d.file("grey.exr") + " -o " + d.file("same.png"));
  ASSERT_EQ(same.code, 0) << same.output;
  EXPECT_NE(same.output.find("RMSE 0,"), std::string::npos) << same.output;
  const envgi::Image blue = envgi::loadImage(d.file("same.png"), false);
  EXPECT_NEAR(blue.at(1, 1).z, 0.6f, 0.01f);
  EXPECT_EQ(blue.at(1, 1).x, 0.f);
  for (float& v : grey.rgb) v = 2.f;
  envgi::saveImage(grey, d.file("bright.exr"));
  ASSERT_EQ(runCli("image diff " + d.file("grey.exr") + " " + d.file("bright.exr") + " -o " + d.file("red.png")).code, 0);
  const envgi::Image red = envgi::loadImage(d.file("red.png"), false);
  EXPECT_NEAR(red.at(0, 0).x, 1.f, 0.01f);
  EXPECT_NEAR(red.at(0, 0).y, 0.f, 0.01f);
  // FLIP (study/FlipError.h): 0 against itself; a flat image eight times brighter gets the
  // reference implementation's 0.2045 (flip-evaluator 1.7: both tone-mapped at one exposure),
  // and --metric flip draws it.
  EXPECT_NE(same.output.find("HDR-FLIP mean 0,"), std::string::npos) << same.output;
  CliResult flip = runCli("image diff " + d.file("grey.exr") + " " + d.file("bright.exr") + " -o " + d.file("flip.png") +
                          " --metric flip");
  ASSERT_EQ(flip.code, 0) << flip.output;
  const size_t at = flip.output.find("HDR-FLIP mean ");
  ASSERT_NE(at, std::string::npos) << flip.output;
  EXPECT_NEAR(std::stod(flip.output.substr(at + 14)), 0.2045, 1e-3) << flip.output;
  const envgi::Color drawn = envgi::loadImage(d.file("flip.png"), false).at(0, 0), zero = blue.at(1, 1);
  EXPECT_GT(std::fabs(drawn.x - zero.x) + std::fabs(drawn.y - zero.y) + std::fabs(drawn.z - zero.z), 0.1f)
      << "past the ramp's blue";
  EXPECT_NE(runCli("image diff " + d.file("grey.exr") + " " + d.file("bright.exr") + " -o " + d.file("x.png") +
                   " --metric ssim").code, 0);
  // Images of two sizes: one error line naming both.
  CliResult sizes = runCli("image diff " + d.file("grey.exr") + " " + d.file("a.pfm") + " -o " + d.file("x.png"));
  EXPECT_EQ(sizes.code, 1) << sizes.output;
  EXPECT_NE(sizes.output.find("envgi: error:"), std::string::npos) << sizes.output;
  EXPECT_FALSE(fs::exists(d.file("x.png")));
}
