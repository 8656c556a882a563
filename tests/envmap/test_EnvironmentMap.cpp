#include <gtest/gtest.h>

#include <filesystem>

#include <unistd.h>

#include <cmath>

#include "envmap/EnvironmentMap.h"

using namespace envgi;

namespace {
Image gradientMap(int w, int h) {
  Image img(w, h);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) img.set(x, y, Color(float(x), float(y), 1.f));
  return img;
}
std::string asset(const std::string& p) { return std::string(ENVGI_ASSETS_DIR) + "/" + p; }
}  // namespace

TEST(EnvironmentMap, MitsubaDirectionConvention) {
  // Row 0 is +Y, the centre column looks along +Z, u = 0.25 along +X.
  auto near = [](Vec3f a, Vec3f b) { return length(a - b) < 1e-5f; };
  EXPECT_TRUE(near(EnvironmentMapView::uvToDir({0.5f, 0.5f}), {0, 0, 1}));
  EXPECT_TRUE(near(EnvironmentMapView::uvToDir({0.25f, 0.5f}), {1, 0, 0}));
  EXPECT_TRUE(near(EnvironmentMapView::uvToDir({0.f, 0.5f}), {0, 0, -1}));
  EXPECT_TRUE(near(EnvironmentMapView::uvToDir({0.3f, 0.f}), {0, 1, 0}));
  for (float u = 0.01f; u < 1.f; u += 0.031f)
    for (float v = 0.01f; v < 1.f; v += 0.029f) {
      Vec2f back = EnvironmentMapView::dirToUV(EnvironmentMapView::uvToDir({u, v}));
      EXPECT_NEAR(back.x, u, 1e-5f);
      EXPECT_NEAR(back.y, v, 1e-5f);
    }
}

TEST(EnvironmentMap, BilinearIsSeamlessAndSaneAtPoles) {
  EnvironmentMap env(gradientMap(16, 8), {});
  auto v = env.view();
  // Across the seam both sides blend the first and last column.
  Color a = v.lookupUV({1e-6f, 0.4f}), b = v.lookupUV({1.f - 1e-6f, 0.4f});
  EXPECT_NEAR(a.x, b.x, 1e-3f);
  EXPECT_NEAR(a.x, 7.5f, 1e-3f);  // halfway between column 15 and column 0
  for (Vec3f d : {Vec3f(0, 1, 0), Vec3f(0, -1, 0), Vec3f(0, 1e-9f, 0)}) {
    Color c = v.eval(normalize(d));
    EXPECT_TRUE(isFiniteVec(c));
  }
  // Pixel centres return pixel values.
  Color c = v.lookupUV({(3 + 0.5f) / 16, (2 + 0.5f) / 8});
  EXPECT_NEAR(c.x, 3.f, 1e-5f);
  EXPECT_NEAR(c.y, 2.f, 1e-5f);
}

TEST(EnvironmentMap, RotationAndScale) {
  EnvironmentMapOptions o;
  o.toWorld = rotate(Vec3f(0, 1, 0), 90.f);
  o.scale = 2.f;
  EnvironmentMap env(gradientMap(64, 32), o);
  auto v = env.view();
  Vec3f local = EnvironmentMapView::uvToDir({0.3f, 0.6f});
  Vec3f world = o.toWorld.vector(local);
  Color expect = v.lookupUV({0.3f, 0.6f});
  Color got = v.eval(world);
  EXPECT_NEAR(got.x, expect.x, 1e-3f);
  EXPECT_NEAR(got.y, expect.y, 1e-3f);
  // scale doubles the pixel value
  EXPECT_NEAR(v.lookupUV({(5 + 0.5f) / 64, (4 + 0.5f) / 32}).x, 10.f, 1e-4f);
}

TEST(EnvironmentMap, InvalidPixelsAreZeroedAndCounted) {
  Image img = gradientMap(8, 4);
  img.rgb[0] = NAN;
  img.rgb[4] = -3.f;
  img.rgb[8] = INFINITY;
  EnvironmentMap env(std::move(img), {});
  EXPECT_EQ(env.invalidPixels(), 3u);
  Image got = env.image();
  EXPECT_EQ(got.rgb[0], 0.f);
  EXPECT_EQ(got.rgb[4], 0.f);
  EXPECT_EQ(got.rgb[8], 0.f);
  EXPECT_EQ(env.stats().invalidPixels, 3u);
}

TEST(EnvironmentMap, AllBlackIsAValidLightOfZeroPower) {
  Image img(16, 8);
  EnvironmentMap env(std::move(img), {});
  EXPECT_EQ(env.luminancePower(), 0.f);
  auto v = env.view();
  for (int s = 0; s < 5; ++s) {
    EnvSample es = v.sample(EnvStrategy(s), {0.37f, 0.61f});
    EXPECT_TRUE(std::isfinite(es.pdf));
    EXPECT_TRUE(isBlack(es.radiance));
    EXPECT_TRUE(isFiniteVec(es.dir));
  }
  EXPECT_EQ(env.stats().top1PercentEnergy, 0.f);
}

TEST(EnvironmentMap, ConstantMapStatistics) {
  EnvironmentMap env = EnvironmentMap::constant(Color(1.f));
  EnvironmentMapStats s = env.stats();
  EXPECT_NEAR(s.power.x, 4.f * kPi, 0.02f);  // integral of 1 over the sphere
  EXPECT_NEAR(env.luminancePower(), 4.f * kPi, 0.02f);
  EXPECT_NEAR(s.lumMeanSolidAngle, 1.f, 1e-5f);
  EXPECT_NEAR(s.top1PercentEnergy, 0.01f, 0.01f);
}

TEST(EnvironmentMap, NegativeScaleIsAnError) {
  EnvironmentMapOptions o;
  o.scale = -1.f;
  EXPECT_THROW(EnvironmentMap(gradientMap(8, 4), o), std::runtime_error);
}

// The HDR and the PFM copy of Grace Cathedral agree: the PFM reader honours bottom-up rows,
// and the brightest pixel lands where the asset README puts it.
TEST(EnvironmentMap, GraceHdrAndPfmAgree) {
  std::string hdr = asset("envmaps/grace/grace_latlong.hdr"), pfm = asset("envmaps/grace/grace_latlong.pfm");
  if (!std::filesystem::exists(hdr) || !std::filesystem::exists(pfm)) GTEST_SKIP() << "Grace maps not in " << ENVGI_ASSETS_DIR;
  Image a = EnvironmentMap::load(hdr).image(), b = EnvironmentMap::load(pfm).image();
  ASSERT_EQ(a.width, 1024);
  ASSERT_EQ(b.height, 512);
  double diff = 0.0, mag = 0.0;
  for (size_t i = 0; i < a.rgb.size(); ++i) {
    diff += std::fabs(a.rgb[i] - b.rgb[i]);
    mag += std::fabs(b.rgb[i]);
  }
  EXPECT_LT(diff / mag, 0.01);
  int bx = 0, by = 0;
  float best = -1.f;
  for (int y = 0; y < 512; ++y)
    for (int x = 0; x < 1024; ++x) {
      float l = luminance(b.at(x, y));
      if (l > best) { best = l; bx = x; by = y; }
    }
  EXPECT_EQ(bx, 502);
  EXPECT_EQ(by, 129);
  EnvironmentMapStats st = EnvironmentMap::load(pfm).stats();
  EXPECT_NEAR(st.lumMeanSolidAngle, 0.0147f, 0.0005f);
}

namespace {
// A map file in the test's own temporary folder, removed with it.
struct MapFile {
  std::filesystem::path path;
  explicit MapFile(const Image& img, const std::string& name) {
    path = std::filesystem::temp_directory_path() / ("envgi_rows_" + std::to_string(::getpid()) + "_" + name + ".pfm");
    saveImage(img, path.string(), SaveOptions{});
  }
  ~MapFile() { std::filesystem::remove(path); }
};
}  // namespace

// A lat-long file is read as Mitsuba reads it: row j at v = j / (H - 1), linear between rows,
// columns at pixel centres. The values below are Mitsuba 3's own envmap.eval on the same 16 x 8
// map (row 3 lit at 1, column 5 at 2), at the same directions.
TEST(EnvironmentMap, LoadedRowsLieOnMitsubasGridFromPoleToPole) {
  const int w = 16, h = 8;
  Image probe(w, h);
  for (int x = 0; x < w; ++x) probe.set(x, 3, Color(1.f));
  for (int y = 0; y < h; ++y) probe.set(5, y, probe.at(5, y) + Color(2.f));
  MapFile file(probe, "probe");
  EnvironmentMap map = EnvironmentMap::load(file.path.string());  // the view reads its texels
  EnvironmentMapView v = map.view();
  struct Probe {
    float u, v, mitsuba;
  };
  for (Probe p : {Probe{1.5f / w, 0.3f, 0.1f}, Probe{1.5f / w, 0.35f, 0.45f}, Probe{1.5f / w, 0.425f, 0.975f},
                  Probe{1.5f / w, 0.5f, 0.5f}, Probe{1.5f / w, 0.5625f, 0.0625f}, Probe{4.6f / w, 0.3f, 0.3f},
                  Probe{5.5f / w, 0.3f, 2.1f}, Probe{6.2f / w, 0.3f, 0.7f}})
    EXPECT_NEAR(v.lookupUV({p.u, p.v}).x, p.mitsuba, 1e-4f) << "u " << p.u << " v " << p.v;
  // The lit row peaks at theta = 3 pi / 7, at the poles the first and last rows hold exactly.
  EXPECT_NEAR(v.lookupUV({1.5f / w, 3.f / 7.f}).x, 1.f, 1e-5f);
  EXPECT_NEAR(v.lookupUV({1.5f / w, 0.f}).x, 0.f, 1e-6f);

  // A map linear in the row: Mitsuba's value v (H - 1) everywhere, the poles included.
  MapFile ramp(gradientMap(w, h), "gradient");  // red = column, green = row
  EnvironmentMap rampMap = EnvironmentMap::load(ramp.path.string());
  EnvironmentMapView r = rampMap.view();
  for (float vv = 0.f; vv <= 1.f; vv += 0.013f) EXPECT_NEAR(r.lookupUV({3.5f / w, vv}).y, vv * float(h - 1), 2e-5f);
  // Built from an image in memory, a map keeps pixel centres (probes and tests use that).
  EnvironmentMap direct(gradientMap(w, h), {});
  EXPECT_NEAR(direct.view().lookupUV({0.5f, 2.5f / h}).y, 2.f, 1e-5f);
  // A nearest-texel map has no grid to move.
  EnvironmentMapOptions nearest;
  nearest.bilinear = false;
  EXPECT_EQ(EnvironmentMap::load(ramp.path.string(), nearest).view().lookupUV({0.5f, 2.5f / h}).y, 2.f);
}

// The resampled rows are Mitsuba's lookup at the pixel centres, each a blend of two rows with
// weights summing to 1: a lit row's energy stays, centred where Mitsuba puts it.
TEST(EnvironmentMap, RowsAtPixelCentresBlendTwoRowsAtMitsubasCoordinate) {
  const int w = 4, h = 64, lit = 20;
  Image row(w, h);
  for (int x = 0; x < w; ++x) row.set(x, lit, Color(1.f));
  Image out = EnvironmentMap::rowsAtPixelCentres(row);
  double sum = 0.0, centroid = 0.0;
  for (int j = 0; j < h; ++j) {
    double y = (j + 0.5) * (h - 1) / double(h);
    float expect = float(std::max(0.0, 1.0 - std::fabs(y - lit)));  // Mitsuba's tent about the row
    EXPECT_NEAR(out.at(1, j).x, expect, 1e-5f) << "row " << j;
    sum += out.at(1, j).x;
    centroid += out.at(1, j).x * (j + 0.5) / h;
  }
  EXPECT_NEAR(sum, double(h) / (h - 1), 1e-3);  // the tent sampled every (h-1)/h rows, about h/(h-1)
  EXPECT_NEAR(centroid / sum, double(lit) / (h - 1), 1e-3) << "the row's light sits at theta = pi j / (H - 1)";
  Image tiny(4, 1);
  EXPECT_EQ(EnvironmentMap::rowsAtPixelCentres(tiny).height, 1);
}

// NaN and negative texels of a file are zeroed and counted before the rows blend: the count is
// the file's, and nothing invalid spreads into the neighbouring rows.
TEST(EnvironmentMap, InvalidTexelsOfAFileAreZeroedBeforeTheRowsBlend) {
  Image img = gradientMap(8, 4);
  img.rgb[0] = NAN;
  img.rgb[4] = -3.f;
  img.rgb[8 * 3 + 2] = INFINITY;
  MapFile file(img, "invalid");
  EnvironmentMap env = EnvironmentMap::load(file.path.string());
  EXPECT_EQ(env.invalidPixels(), 3u);
  Image got = env.image();
  for (float c : got.rgb) EXPECT_TRUE(std::isfinite(c) && c >= 0.f);
}
