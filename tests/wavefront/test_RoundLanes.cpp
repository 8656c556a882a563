// RoundLanes makes a round's camera samples lane by lane: the rays, filter weights and sampler
// positions must be the one-sample path's (Sampler::startPixel, then sampleCameraRay) to the
// bit, whatever the camera, filter or sample count, and where the rays meet the map must be
// EnvironmentMapView::eval's (u, v).
#include <gtest/gtest.h>

#include <cstring>

#include "wavefront/RoundLanes.h"
#include "materials/BsdfFactory.h"
#include "wavefront/TileWavefront.h"
#include "sampling/Pcg32.h"

using namespace envgi;

namespace {

bool sameBits(float a, float b) { return std::memcmp(&a, &b, sizeof(float)) == 0; }

Camera testCamera(int w, int h) {
  Camera c;
  c.width = w;
  c.height = h;
  c.tanHalfY = std::tan(0.5f * 35.f * kPi / 180.f);
  c.tanHalfX = c.tanHalfY * float(w) / float(h);
  c.nearClip = 0.03f;
  c.farClip = 800.f;
  c.toWorld = lookAt(Vec3f(1.f, 2.f, 6.f), Vec3f(0.f, 0.5f, 0.f), Vec3f(0.2f, 1.f, 0.f));
  return c;
}

// Every sample of a 37 x 23 image (lanes not a multiple of any vector width) both ways.
void expectSameSamples(const Camera& cam, uint32_t spp, uint32_t seed, const char* what) {
  RoundLanes cr;
  SampleSequence seq{SamplerType::Sobol, spp, seed};
  int mismatches = 0;
  for (uint32_t s = 0; s < spp; ++s) {
    Sampler first = sequenceSampler(seq);
    first.setIndex(s);
    const int n = cam.width * cam.height;
    cr.resize(size_t(n));
    for (int i = 0; i < n; ++i) cr.px[i] = i % cam.width, cr.py[i] = i / cam.width;
    cr.make(cam, first, n);
    for (int i = 0; i < n; ++i) {
      Sampler one = sequenceSampler(seq);
      float w;
      const Ray r = startCameraSample(cam, one, cr.px[i], cr.py[i], int(s), &w);
      Sampler lanes = first;
      lanes.startPixelAt(cr.hash[i], RoundLanes::dimensions(cam));
      const Ray q = cr.rayOf(i);
      const bool same = sameBits(r.o.x, q.o.x) && sameBits(r.o.y, q.o.y) && sameBits(r.o.z, q.o.z) &&
                        sameBits(r.d.x, q.d.x) && sameBits(r.d.y, q.d.y) && sameBits(r.d.z, q.d.z) &&
                        sameBits(r.tMax, q.tMax) && sameBits(w, cr.weight[i]) && one.pixelHash == lanes.pixelHash &&
                        one.dim == lanes.dim;
      // The sampler goes on from the same place: its next draws are the same.
      const Vec2f a = one.get2D(), b = lanes.get2D();
      if (!same || !sameBits(a.x, b.x) || !sameBits(a.y, b.y)) ++mismatches;
    }
  }
  EXPECT_EQ(mismatches, 0) << what << ", spp " << spp;
}

}  // namespace

TEST(RoundLanes, SamplesAreTheOneSamplePathsToTheBit) {
  for (uint32_t spp : {1u, 8u, 6u}) {
    Camera pinhole = testCamera(37, 23);
    pinhole.filter = makeFilter(FilterType::Box);
    expectSameSamples(pinhole, spp, 0, "pinhole, box");
    expectSameSamples(pinhole, spp, 77, "pinhole, box, seed 77");
    pinhole.filter = makeFilter(FilterType::Gaussian);
    expectSameSamples(pinhole, spp, 3, "pinhole, gaussian");
    pinhole.filter = makeFilter(FilterType::Mitchell);
    expectSameSamples(pinhole, spp, 3, "pinhole, mitchell");
    Camera crop = testCamera(37, 23);
    crop.filmWidth = 100, crop.filmHeight = 60, crop.cropX = 31, crop.cropY = 17;
    expectSameSamples(crop, spp, 5, "a crop window");
    Camera lens = testCamera(37, 23);
    lens.apertureRadius = 0.1f;
    lens.focusDistance = 5.f;
    expectSameSamples(lens, spp, 9, "a thin lens");
    Camera ortho = testCamera(37, 23);
    ortho.orthographic = true;
    expectSameSamples(ortho, spp, 11, "orthographic");
  }
}

TEST(RoundLanes, RaysMeetTheMapWhereEvalLooksItUp) {
  EnvironmentMapView env;
  env.toWorld = rotate(Vec3f(0.3f, 1.f, 0.2f), 25.f);
  RoundLanes cr;
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
  cr.mapUV(env, n);
  int mismatches = 0;
  for (int i = 0; i < n; ++i) {
    const Vec2f uv = EnvironmentMapView::dirToUV(env.toLocalUnnormalized(Vec3f(cr.dx[i], cr.dy[i], cr.dz[i])));
    if (!sameBits(uv.x, cr.u[i]) || !sameBits(uv.y, cr.v[i])) ++mismatches;
    EXPECT_GE(cr.u[i], 0.f);
    EXPECT_LT(cr.u[i], 1.f);
  }
  EXPECT_EQ(mismatches, 0);
}

// The camera round's escaped rays take the map's radiance from the lanes (mapRadiance): the same
// to the bit as lookupUV, bilinear or not, with rows at pixel centres or from pole to pole, at the
// seam, the poles and the map's last texels, for picked lanes in any order.
TEST(RoundLanes, LookupsInLanesAreLookupUVToTheBit) {
  const int w = 37, h = 19;
  std::vector<float> texels(size_t(w) * h * 4);
  Pcg32 rng(11);
  for (float& t : texels) t = 10.f * rng.nextFloat() * rng.nextFloat();
  RoundLanes cr;
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
    cr.mapRadiance(env, n);
    int mismatches = 0;
    for (int j = 0; j < n; ++j) {
      const Color c = env.lookupUV(cr.uvOf(cr.picked[j]));
      const Color l = cr.radianceOf(j);
      if (!sameBits(c.x, l.x) || !sameBits(c.y, l.y) || !sameBits(c.z, l.z)) ++mismatches;
    }
    EXPECT_EQ(mismatches, 0) << "variant " << variant;
  }
}

// A round's product draws placed inside their pixels in lanes (placeDraws) land where
// EnvironmentMapView::placeInPixel places them, with its density factor and lookupUV's radiance
// there, to the bit: in pixels that warp and pixels that do not, and at pixels' far edges, where
// insidePixel steps the point back (the lanes redo those one at a time).
TEST(RoundLanes, DrawsPlacedInLanesAreThePlacedDrawsToTheBit) {
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
  RoundLanes cr;
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

namespace {
// Eight rough plastics with their coat's tables: four roughnesses, one- and two-sided, linear
// and nonlinear bases, two coats.
Bsdf roughPlasticVariant(int variant) {
  Bsdf b;
  b.type = BsdfType::RoughPlastic;
  b.alpha = variant % 4 == 0 ? 0.02f : (variant % 4 == 1 ? 0.12f : (variant % 4 == 2 ? 0.5f : 1.7f));
  b.twoSided = variant % 2 == 0;
  b.nonlinear = variant / 2 % 2 == 1;
  b.reflectance = Color(0.55f, 0.45f, 0.3f);
  b.specularReflectance = variant < 4 ? Color(1.f) : Color(0.9f, 0.8f, 0.6f);
  b.ior = variant < 4 ? 1.49f : 1.8f;
  finishPlastic(b);
  attachRoughCoat(b);
  return b;
}
}  // namespace

// A round's rough plastic samples in lanes (sampleRoughPlastic) are bsdfSample's with the lobe
// from u (path's and direct's call), to the bit, or fail where it fails: one- and two-sided,
// linear and nonlinear bases, several roughnesses, wo in both hemispheres and at grazing angles,
// draws at the lobes' boundary and at the unit square's edges and centre.
TEST(RoundLanes, RoughPlasticSamplesInLanesAreBsdfSampleToTheBit) {
  Pcg32 rng(31);
  int cases = 0, failures = 0, coat = 0, base = 0, none = 0;
  for (int variant = 0; variant < 8; ++variant) {
    const Bsdf b = roughPlasticVariant(variant);
    ASSERT_TRUE(RoundLanes::samplesInLanes(b)) << "variant " << variant;
    const int n = 601;
    RoundLanes lanes;
    lanes.resize(size_t(n));
    std::vector<Vec3f> wos(n);
    std::vector<Vec2f> us(n);
    for (int j = 0; j < n; ++j) {
      Vec3f wo = sampleUniformSphere(Vec2f(rng.nextFloat(), rng.nextFloat()));
      if (j % 7 == 0) wo = normalize(Vec3f(wo.x, wo.y, 1e-4f * wo.z));  // grazing
      if (j == 1) wo = Vec3f(0.f, 0.f, 1.f);
      if (j == 2) wo = Vec3f(0.f, 0.f, -1.f);
      Vec2f u(rng.nextFloat(), rng.nextFloat());
      if (j % 11 == 0) u = Vec2f(0.5f, 0.5f);  // the concentric disk's centre
      if (j % 13 == 0) u = Vec2f(u.x, 0.f);
      if (j % 17 == 0) u = Vec2f(kOneMinusEpsilon, u.y);
      wos[j] = wo, us[j] = u;
      lanes.setBsdfDraw(j, wo, u);
    }
    lanes.sampleRoughPlastic(b, n);
    for (int j = 0; j < n; ++j) {
      BsdfSample one, inLanes;
      const bool ok = bsdfSample(b, wos[j], 0.f, us[j], &one, true);
      const bool okLanes = lanes.bsdfSampleOf(j, &inLanes);
      ++cases;
      if (ok != okLanes) {
        ++failures;
        ADD_FAILURE() << "variant " << variant << " lane " << j << ": bsdfSample " << ok << ", lanes " << okLanes;
        continue;
      }
      if (!ok) {
        ++none;
        continue;
      }
      (lanes.coatLobe[j] > 0.5f ? coat : base) += 1;
      EXPECT_TRUE(sameBits(one.wi.x, inLanes.wi.x) && sameBits(one.wi.y, inLanes.wi.y) &&
                  sameBits(one.wi.z, inLanes.wi.z) && sameBits(one.weight.x, inLanes.weight.x) &&
                  sameBits(one.weight.y, inLanes.weight.y) && sameBits(one.weight.z, inLanes.weight.z) &&
                  sameBits(one.pdf, inLanes.pdf) && !inLanes.delta)
          << "variant " << variant << " lane " << j;
    }
  }
  EXPECT_EQ(failures, 0);
  EXPECT_EQ(cases, 8 * 601);
  // Both lobes compared, and the failures' cases reached (a wo below a one-sided surface).
  EXPECT_GT(coat, 300);
  EXPECT_GT(base, 1000);
  EXPECT_GT(none, 300);
}

// A round's rough plastic evaluations in lanes (evalRoughPlastic) are bsdfEvalPdf's, value and
// density, to the bit: one- and two-sided, linear and nonlinear, wo and wi on either side.
TEST(RoundLanes, RoughPlasticEvaluationsInLanesAreBsdfEvalPdfToTheBit) {
  Pcg32 rng(37);
  int compared = 0, zero = 0;
  for (int variant = 0; variant < 8; ++variant) {
    const Bsdf b = roughPlasticVariant(variant);
    const int n = 503;
    RoundLanes lanes;
    lanes.resize(size_t(n));
    std::vector<Vec3f> wos(n), wis(n);
    for (int j = 0; j < n; ++j) {
      wos[j] = sampleUniformSphere(Vec2f(rng.nextFloat(), rng.nextFloat()));
      wis[j] = sampleUniformSphere(Vec2f(rng.nextFloat(), rng.nextFloat()));
      if (j % 9 == 0) wis[j] = Vec3f(-wos[j].x, -wos[j].y, wos[j].z);  // the mirror direction
      lanes.setBsdfEval(j, wos[j], wis[j]);
    }
    lanes.evalRoughPlastic(b, n);
    for (int j = 0; j < n; ++j) {
      float pdf;
      const Color f = bsdfEvalPdf(b, wos[j], wis[j], &pdf);
      const LaneBsdfValue e = lanes.bsdfEvalOf(j);
      EXPECT_TRUE(sameBits(f, e.f) && sameBits(Vec3f(pdf, 0.f, 0.f), Vec3f(e.pdf, 0.f, 0.f)) &&
                  sameBits(e.wi, wis[j]))
          << "variant " << variant << " lane " << j;
      ++compared;
      zero += pdf == 0.f;
    }
  }
  EXPECT_EQ(compared, 8 * 503);
  EXPECT_GT(zero, 500) << "the directions below the surface were not reached";
  EXPECT_LT(zero, 3000);
}
