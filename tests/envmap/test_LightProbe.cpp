#include <gtest/gtest.h>

#include <cmath>
#include <stdexcept>

#include "envmap/EnvironmentMap.h"
#include "envmap/LightProbe.h"

using namespace envgi;

namespace {

std::string bundled(const std::string& name) { return std::string(ENVGI_SOURCE_DIR) + "/scenes/envmaps/" + name; }

// A probe whose every pixel holds f of the direction at its centre (black outside the disk).
template <class F>
Image probeOf(ProbeLayout layout, int n, F f) {
  Image img(n, n);
  for (int y = 0; y < n; ++y)
    for (int x = 0; x < n; ++x) {
      Vec2f p((float(x) + 0.5f) / float(n) * 2.f - 1.f, 1.f - (float(y) + 0.5f) / float(n) * 2.f);
      if (p.x * p.x + p.y * p.y <= 1.f) img.set(x, y, f(probeDiskDirection(layout, p)));
    }
  return img;
}

// The lat-long map's direction at pixel (x, y)'s centre, in the probe's frame.
Vec3f probeDirAt(const Image& map, int x, int y) {
  return latLongToProbeFrame(EnvironmentMapView::uvToDir(
      {(float(x) + 0.5f) / float(map.width), (float(y) + 0.5f) / float(map.height)}));
}

}  // namespace

TEST(LightProbe, DiskPointsOfTheAxes) {
  // Forward in the centre, up at the top, +X on the right of an angular map and on the left of
  // a mirror ball; 90 degrees off forward lands at half the radius on an angular map and at
  // sin 45 on a mirror ball; backward on the rim.
  for (ProbeLayout l : {ProbeLayout::Angular, ProbeLayout::MirrorBall}) {
    float side = l == ProbeLayout::Angular ? 0.5f : std::sqrt(0.5f);
    float across = l == ProbeLayout::Angular ? side : -side;
    Vec2f c = probeDiskPoint(l, {0, 0, -1}), r = probeDiskPoint(l, {1, 0, 0}), u = probeDiskPoint(l, {0, 1, 0});
    EXPECT_NEAR(c.x, 0.f, 1e-7f);
    EXPECT_NEAR(c.y, 0.f, 1e-7f);
    EXPECT_NEAR(r.x, across, 1e-6f);
    EXPECT_NEAR(r.y, 0.f, 1e-7f);
    EXPECT_NEAR(u.x, 0.f, 1e-7f);
    EXPECT_NEAR(u.y, side, 1e-6f);
    Vec2f b = probeDiskPoint(l, {0, 0, 1});
    EXPECT_NEAR(std::sqrt(b.x * b.x + b.y * b.y), 1.f, 1e-6f) << "backward is the rim";
  }
}

TEST(LightProbe, DiskPointAndDirectionAreInverses) {
  for (ProbeLayout l : {ProbeLayout::Angular, ProbeLayout::MirrorBall})
    for (float t = 0.013f; t < 0.995f; t += 0.047f)
      for (float phi = 0.f; phi < 6.28f; phi += 0.39f) {
        // Directions off the poles of the (u, v) sphere: theta from forward up to near backward.
        float theta = t * kPi;
        Vec3f d(std::sin(theta) * std::cos(phi), std::sin(theta) * std::sin(phi), -std::cos(theta));
        Vec3f back = probeDiskDirection(l, probeDiskPoint(l, d));
        EXPECT_LT(length(back - d), 2e-5f) << "theta " << theta << " phi " << phi;
      }
}

TEST(LightProbe, OrientationInTheLatLongMap) {
  // A probe that is red to the forward side, green up and blue to the right: the map has the
  // forward direction in its centre column at the horizon, the top row up, and the probe's +X
  // a quarter turn to the right of the centre (u = 0.75), as HDRShop's panoramas do.
  for (ProbeLayout l : {ProbeLayout::Angular, ProbeLayout::MirrorBall}) {
    Image probe = probeOf(l, 256, [](Vec3f d) {
      return Color(std::max(-d.z, 0.f), std::max(d.y, 0.f), std::max(d.x, 0.f));
    });
    Image map = probeToLatLong(probe, l);
    ASSERT_EQ(map.width, 512);
    ASSERT_EQ(map.height, 256);
    EXPECT_GT(map.at(256, 128).x, 0.97f) << "forward in the centre";
    EXPECT_GT(map.at(100, 0).y, 0.97f) << "up in the top row";
    EXPECT_GT(map.at(384, 128).z, 0.97f) << "+X at u = 0.75";
    EXPECT_LT(map.at(128, 128).z, 0.03f) << "-X at u = 0.25";
  }
}

TEST(LightProbe, MapFollowsTheProbeEverywhere) {
  // A smooth function of direction survives the resampling to within the bilinear lookups'
  // error, the back hemisphere included (where a mirror ball squeezes it into the rim).
  auto f = [](Vec3f d) { return Color(1.f + d.x, 1.f + d.y * d.z, 1.5f - d.z); };
  for (ProbeLayout l : {ProbeLayout::Angular, ProbeLayout::MirrorBall}) {
    Image map = probeToLatLong(probeOf(l, 512, f), l, {256, 0});
    double worst = 0.0, sum = 0.0;
    for (int y = 0; y < map.height; ++y)
      for (int x = 0; x < map.width; ++x) {
        Vec3f d = probeDirAt(map, x, y);
        if (d.z > 0.95f) continue;  // the last few degrees before backward lie on the rim itself
        Color e = map.at(x, y) - f(d);
        double err = std::max({std::fabs(e.x), std::fabs(e.y), std::fabs(e.z)});
        worst = std::max(worst, err);
        sum += err;
      }
    EXPECT_LT(worst, l == ProbeLayout::Angular ? 0.02 : 0.1);
    EXPECT_LT(sum / (map.width * map.height), 0.004);
  }
}

TEST(LightProbe, ConstantProbeGivesAConstantMap) {
  // The rim is not blended with the black corners outside the disk.
  Image probe = probeOf(ProbeLayout::Angular, 64, [](Vec3f) { return Color(2.f, 1.f, 0.5f); });
  Image map = probeToLatLong(probe, ProbeLayout::Angular);
  for (int y = 0; y < map.height; ++y)
    for (int x = 0; x < map.width; ++x) {
      ASSERT_NEAR(map.at(x, y).x, 2.f, 1e-5f) << x << "," << y;
      ASSERT_NEAR(map.at(x, y).z, 0.5f, 1e-5f) << x << "," << y;
    }
}

TEST(LightProbe, SmallMapsAverageTheProbeInsteadOfAliasing) {
  // A one-pixel checkerboard probe made into a map 1/8 of its width: each map pixel covers many
  // probe pixels, which the default count of lookups averages; one lookup a pixel does not.
  Image probe(256, 256);
  for (int y = 0; y < 256; ++y)
    for (int x = 0; x < 256; ++x) probe.set(x, y, Color(float((x + y) & 1)));
  auto worst = [&](int n) {
    Image map = probeToLatLong(probe, ProbeLayout::Angular, {64, n});
    float w = 0.f;
    for (int y = 4; y < map.height - 4; ++y)  // the poles' rows span a sliver of the probe
      for (int x = 0; x < map.width; ++x) w = std::max(w, std::fabs(map.at(x, y).x - 0.5f));
    return w;
  };
  EXPECT_LT(worst(0), 0.2f);
  EXPECT_GT(worst(1), 0.3f);
}

TEST(LightProbe, MatchesTheGallerysConversionOfUffizi) {
  // The bundled 128^2 Uffizi probe against its lat-long conversion in the asset collection (made
  // independently, bilinear, the same layout; stored as RGBE, negatives clamped after lookup).
  Image probe = loadImage(bundled("uffizi_probe_128.exr"));
  Image ref = loadImage(bundled("uffizi_probe_128_latlong_256x128.hdr"));
  Image map = probeToLatLong(probe, ProbeLayout::Angular);
  ASSERT_EQ(map.width, ref.width);
  ASSERT_EQ(map.height, ref.height);
  double sa = 0, sb = 0, saa = 0, sbb = 0, sab = 0, se = 0;
  size_t n = map.rgb.size();
  for (size_t i = 0; i < n; ++i) {
    double a = map.rgb[i], b = ref.rgb[i];
    sa += a, sb += b, saa += a * a, sbb += b * b, sab += a * b, se += (a - b) * (a - b);
  }
  double corr = (sab - sa * sb / n) / std::sqrt((saa - sa * sa / n) * (sbb - sb * sb / n));
  EXPECT_GT(corr, 0.9999);
  EXPECT_LT(std::sqrt(se / n) / (sb / n), 0.03) << "RMSE relative to the mean";
  EXPECT_NEAR(sa / sb, 1.0, 0.01);
}

TEST(LightProbe, BadProbesAreErrors) {
  auto message = [](const Image& img, ProbeConversion c = {}) {
    try {
      probeToLatLong(img, ProbeLayout::Angular, c);
    } catch (const std::runtime_error& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  EXPECT_NE(message(Image(64, 32)).find("square image of at least 2x2, not 64x32 (this looks like a lat-long map"),
            std::string::npos);
  EXPECT_NE(message(Image(1, 1)).find("square image of at least 2x2, not 1x1"), std::string::npos);
  EXPECT_NE(message(Image(8, 8), {13, 0}).find("must be even, from 2 to 32768, not 13"), std::string::npos);
  // Mistyped sizes are refused before anything is allocated or looped over.
  EXPECT_NE(message(Image(8, 8), {2000000000, 0}).find("not 2000000000"), std::string::npos);
  EXPECT_NE(message(Image(8, 8), {16, 100000}).find("at most 64 x 64 lookups a map pixel, not 100000"),
            std::string::npos);
  EXPECT_THROW(parseProbeLayout("cubemap"), std::runtime_error);

  Image nan = probeOf(ProbeLayout::Angular, 16, [](Vec3f) { return Color(1.f); });
  nan.set(8, 8, Color(NAN, -1.f, INFINITY));
  size_t invalid = 0;
  Image map = probeToLatLong(nan, ProbeLayout::Angular, {}, &invalid);
  EXPECT_EQ(invalid, 3u);
  for (float v : map.rgb) ASSERT_TRUE(std::isfinite(v) && v >= 0.f);
}

TEST(LightProbe, EnvironmentMapReadsAProbeAsItsConversion) {
  EnvironmentMap env = EnvironmentMap::loadProbe(bundled("uffizi_probe_128.exr"), ProbeLayout::Angular);
  Image direct = probeToLatLong(loadImage(bundled("uffizi_probe_128.exr")), ProbeLayout::Angular);
  Image got = env.image();
  ASSERT_EQ(got.width, direct.width);
  ASSERT_EQ(got.rgb.size(), direct.rgb.size());
  for (size_t i = 0; i < direct.rgb.size(); ++i) ASSERT_EQ(got.rgb[i], direct.rgb[i]);
  EXPECT_GT(env.luminancePower(), 0.f);
  EXPECT_THROW(EnvironmentMap::loadProbe(bundled("studio.hdr"), ProbeLayout::Angular), std::runtime_error)
      << "a lat-long map is not a probe";
}

namespace {

// The direction at a continuous point (X, Y) of a cube cross of face size n (pixel units).
Vec3f crossDirection(bool vertical, int n, float X, float Y) {
  for (int f = 0; f < 6; ++f) {
    int col, row;
    crossCell(f, vertical, &col, &row);
    float fx = X - float(col * n), fy = Y - float(row * n);
    if (fx >= 0.f && fx <= float(n) && fy >= 0.f && fy <= float(n))
      return cubeFaceDirection(f, {fx / float(n) * 2.f - 1.f, 1.f - fy / float(n) * 2.f}, !vertical);
  }
  return Vec3f(0.f);
}

// A cross whose every face pixel holds f of the direction at its centre.
template <class F>
Image crossOf(bool vertical, int n, F f) {
  Image img(vertical ? 3 * n : 4 * n, vertical ? 4 * n : 3 * n);
  for (int face = 0; face < 6; ++face) {
    int col, row;
    crossCell(face, vertical, &col, &row);
    for (int y = 0; y < n; ++y)
      for (int x = 0; x < n; ++x)
        img.set(col * n + x, row * n + y,
                f(cubeFaceDirection(face, {(float(x) + 0.5f) / float(n) * 2.f - 1.f, 1.f - (float(y) + 0.5f) / float(n) * 2.f},
                                    !vertical)));
  }
  return img;
}

}  // namespace

TEST(LightProbe, CubeFacePointAndDirectionAreInverses) {
  for (bool upright : {false, true})
    for (float t = 0.013f; t < 0.995f; t += 0.047f)
      for (float phi = 0.f; phi < 6.28f; phi += 0.39f) {
        float theta = t * kPi;
        Vec3f d(std::sin(theta) * std::cos(phi), std::cos(theta), std::sin(theta) * std::sin(phi));
        CubeFacePoint p = cubeFacePoint(d, upright);
        ASSERT_LE(std::fabs(p.st.x), 1.f);
        ASSERT_LE(std::fabs(p.st.y), 1.f);
        EXPECT_LT(length(cubeFaceDirection(p.face, p.st, upright) - d), 1e-5f);
      }
  // The forward face looks along -Z with +X to the right and +Y up.
  EXPECT_LT(length(cubeFaceDirection(5, {1.f, 0.f}, false) - normalize(Vec3f(1, 0, -1))), 1e-6f);
  EXPECT_LT(length(cubeFaceDirection(5, {0.f, 1.f}, false) - normalize(Vec3f(0, 1, -1))), 1e-6f);
}

TEST(LightProbe, CrossFacesMeetAlongTheirSharedEdges) {
  // Wherever two faces touch in the cross, both give the same direction along the edge, so the
  // cross folds into a cube: the vertical cross's upside-down backward face under the downward
  // one, the horizontal cross's upright one right of the +X face.
  const int n = 8;
  for (bool vertical : {true, false}) {
    int w = vertical ? 3 * n : 4 * n, h = vertical ? 4 * n : 3 * n;
    int shared = 0;
    for (int f = 0; f < 6; ++f) {
      int col, row;
      crossCell(f, vertical, &col, &row);
      // Just inside this face and just across its right and bottom edges.
      for (float a = 0.5f; a < float(n); a += 1.f) {
        float eps = 1e-3f;
        float rx = float((col + 1) * n), by = float((row + 1) * n);
        if (rx + eps < float(w)) {
          Vec3f in = crossDirection(vertical, n, rx - eps, float(row * n) + a);
          Vec3f out = crossDirection(vertical, n, rx + eps, float(row * n) + a);
          if (lengthSq(out) > 0.f) {
            EXPECT_LT(length(in - out), 1e-2f) << "face " << f << " right edge";
            ++shared;
          }
        }
        if (by + eps < float(h)) {
          Vec3f in = crossDirection(vertical, n, float(col * n) + a, by - eps);
          Vec3f out = crossDirection(vertical, n, float(col * n) + a, by + eps);
          if (lengthSq(out) > 0.f) {
            EXPECT_LT(length(in - out), 1e-2f) << "face " << f << " bottom edge";
            ++shared;
          }
        }
      }
    }
    EXPECT_EQ(shared, 5 * n) << "five shared edges in a cross of six faces";
  }
}

TEST(LightProbe, CrossMapFollowsTheProbe) {
  auto f = [](Vec3f d) { return Color(1.f + d.x, 1.f + d.y * d.z, 1.5f - d.z); };
  for (bool vertical : {true, false}) {
    Image cross = crossOf(vertical, 64, f);
    Image map = probeToLatLong(cross, ProbeLayout::Cross);
    ASSERT_EQ(map.width, 256) << "four face widths";
    double worst = 0.0;
    for (int y = 0; y < map.height; ++y)
      for (int x = 0; x < map.width; ++x) {
        Color e = map.at(x, y) - f(probeDirAt(map, x, y));
        worst = std::max({worst, double(std::fabs(e.x)), double(std::fabs(e.y)), double(std::fabs(e.z))});
      }
    EXPECT_LT(worst, 0.03) << (vertical ? "vertical" : "horizontal");
  }
  EXPECT_NE(std::string(probeLayoutName(ProbeLayout::Cross)), "?");
}

TEST(LightProbe, CrossOfTheWrongShapeIsAnError) {
  for (const Image& img : {Image(64, 64), Image(30, 41), Image(5, 2)}) {
    try {
      probeToLatLong(img, ProbeLayout::Cross);
      ADD_FAILURE() << img.width << "x" << img.height << " converted";
    } catch (const std::runtime_error& e) {
      EXPECT_NE(std::string(e.what()).find("a cube cross is 3N x 4N (vertical) or 4N x 3N (horizontal) pixels, not"),
                std::string::npos)
          << e.what();
    }
  }
  EXPECT_EQ(probeToLatLong(Image(3, 4), ProbeLayout::Cross).width, 4) << "one pixel a face";
}
