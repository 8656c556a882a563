// MapLanes, the map's batch forms: where directions meet the map (EnvironmentMapView::eval's
// (u, v)), the radiance there (lookupUV's) and product draws placed in their pixels
// (placeInPixel's), each to the bit.
#include <gtest/gtest.h>

#include <cstring>

#include "envmap/MapLanes.h"
#include "sampling/Pcg32.h"
#include "sampling/Warp.h"

using namespace envgi;

namespace {
bool sameBits(float a, float b) { return std::memcmp(&a, &b, sizeof(float)) == 0; }
}  // namespace

TEST(MapLanes, RaysMeetTheMapWhereEvalLooksItUp) {
  EnvironmentMapView env;
  env.toWorld = rotate(Vec3f(0.3f, 1.f, 0.2f), 25.f);
  MapLanes cr;
  const int n = 1001;
  cr.resize(size_t(n));
  Pcg32 rng(5);
  for (int i = 0; i < n; ++i) {
    Vec3f d = sampleUniformSphere(Vec2f(rng.nextFloat(), rng.nextFloat()));
    // The poles, the seam and the axes, where atan2's quadrants and zeros decide.
    if (i < 12) {
      const Vec3f special[12] = {{0, 1, 0}, {0, -1, 0}, {1, 0, 0}, {-1, 0, 0}, {0, 0, 1}, {0, 0, -1},
                                 {0, 0.f, -1e-30f}, {1e-30f, 1, 0}, {-0.f, 0, -1}, {0.6f, 0.8f, 0}, {0, 0.8f, 0.6f}, {1, 1, 1}};
      d = env.toWorld.vector(special[i]);
    }
    cr.dx[i] = d.x, cr.dy[i] = d.y, cr.dz[i] = d.z;
  }
  cr.findUV(env, n);
  int mismatches = 0;
  for (int i = 0; i < n; ++i) {
    const Vec2f uv = EnvironmentMapView::dirToUV(env.toLocalUnnormalized(Vec3f(cr.dx[i], cr.dy[i], cr.dz[i])));
    if (!sameBits(uv.x, cr.u[i]) || !sameBits(uv.y, cr.v[i])) ++mismatches;
    EXPECT_GE(cr.u[i], 0.f);
    EXPECT_LT(cr.u[i], 1.f);
  }
  EXPECT_EQ(mismatches, 0);
}

// The map's radiance looked up in lanes (lookUp): the same
// to the bit as lookupUV, bilinear or not, with rows at pixel centres or from pole to pole, at the
// seam, the poles and the map's last texels, for picked lanes in any order.
TEST(MapLanes, LookupsInLanesAreLookupUVToTheBit) {
  const int w = 37, h = 19;
  std::vector<float> texels(size_t(w) * h * 4);
  Pcg32 rng(11);
  for (float& t : texels) t = 10.f * rng.nextFloat() * rng.nextFloat();
  MapLanes cr;
  const int n = 613;
  cr.resize(size_t(n));
  for (int i = 0; i < n; ++i) {
    cr.u[i] = rng.nextFloat(), cr.v[i] = rng.nextFloat();
    if (i < 8) {
      const float edges[8][2] = {{0.f, 0.f}, {kOneMinusEpsilon, kOneMinusEpsilon}, {0.f, 1.f}, {0.5f / w, 0.5f / h},
                                 {kOneMinusEpsilon, 0.5f}, {1e-7f, 1e-7f}, {0.5f, 0.f}, {0.5f, 1.f}};
      cr.u[i] = edges[i][0], cr.v[i] = edges[i][1];
    }
    cr.picked[i] = (i * 389) % n;  // every lane once, out of order
  }
  for (int variant = 0; variant < 3; ++variant) {
    EnvironmentMapView env;
    env.texels = texels.data();
    env.width = w, env.height = h;
    env.scale = 1.7f;
    env.bilinear = variant != 0;
    env.rowsFromPoles = variant == 2;
    for (float& x : cr.red) x = -1.f;
    cr.lookUp(env, n);
    int mismatches = 0;
    for (int j = 0; j < n; ++j) {
      const Color c = env.lookupUV(cr.uvOf(cr.picked[j]));
      const Color l = cr.radianceOf(j);
      if (!sameBits(c.x, l.x) || !sameBits(c.y, l.y) || !sameBits(c.z, l.z)) ++mismatches;
    }
    EXPECT_EQ(mismatches, 0) << "variant " << variant;
  }
}

// Product draws placed inside their pixels in lanes (placeDraws) land where
// EnvironmentMapView::placeInPixel places them, with its density factor and lookupUV's radiance
// there, to the bit: in pixels that warp and pixels that do not, and at pixels' far edges, where
// insidePixel steps the point back (the lanes redo those one at a time).
TEST(MapLanes, DrawsPlacedInLanesAreThePlacedDrawsToTheBit) {
  const int w = 29, h = 15;
  std::vector<float> texels(size_t(w) * h * 4);
  Pcg32 rng(23);
  for (size_t i = 0; i < texels.size(); ++i) {
    // Bright spots beside dark ones (the warp's case), and some black pixels.
    const float t = rng.nextFloat();
    texels[i] = t < 0.1f ? 0.f : (t > 0.9f ? 50.f * t : t);
  }
  for (size_t i = 0; i < size_t(w) * h; ++i)
    texels[i * 4 + 3] = luminance(texels[i * 4], texels[i * 4 + 1], texels[i * 4 + 2]);
  std::vector<uint32_t> bits((size_t(w) * h + 31) / 32);
  for (uint32_t& b : bits) b = rng.nextUInt() | 0x11111111u;  // most pixels warp, some do not
  EnvironmentMapView env;
  env.texels = texels.data();
  env.width = w, env.height = h;
  env.scale = 2.5f;
  env.warpBits = bits.data();
  MapLanes cr;
  const int n = 777;
  cr.resize(size_t(n));
  std::vector<Vec2f> uvs(n);
  std::vector<float> pdfs(n);
  for (int j = 0; j < n; ++j) {
    Vec2f uv(rng.nextFloat(), rng.nextFloat());
    if (j % 3 == 0) {  // a pixel's far edge, across or down or both
      const int px = int(rng.nextFloat() * w), py = int(rng.nextFloat() * h);
      const float ex = nextafterf(float(px + 1) / float(w), 0.f), ey = nextafterf(float(py + 1) / float(h), 0.f);
      uv = Vec2f(j % 2 ? ex : uv.x, j % 5 ? ey : uv.y);
    }
    uvs[j] = uv;
    pdfs[j] = 0.1f + 3.f * rng.nextFloat();
    cr.setDraw(j, uv, pdfs[j]);
  }
  cr.placeDraws(env, n);
  int mismatches = 0, redone = 0;
  for (int j = 0; j < n; ++j) {
    float pdf = pdfs[j];
    const Vec2f placed = env.placeInPixel(uvs[j], &pdf);
    const Color L = env.lookupUV(placed);
    Vec2f luv;
    float lpdf;
    Color lL;
    cr.placedDraw(j, &luv, &lpdf, &lL);
    if (!sameBits(placed.x, luv.x) || !sameBits(placed.y, luv.y) || !sameBits(pdf, lpdf) || !sameBits(L.x, lL.x) ||
        !sameBits(L.y, lL.y) || !sameBits(L.z, lL.z))
      ++mismatches;
    redone += cr.redo[j];
  }
  EXPECT_EQ(mismatches, 0);
  EXPECT_GT(redone, 0) << "no draw took insidePixel's steps: the edge cases no longer reach them";
}
