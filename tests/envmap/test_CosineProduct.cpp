// The product strategy: its cosine bound really bounds the cosine (so no direction a reflecting
// BSDF can use is left without density), and it pays: lower variance than Algorithm 1's density
// for irradiance, with the same mean. The chi-square and pdf checks are in
// test_EnvironmentSampling.cpp with the other strategies.
#include <gtest/gtest.h>

#include "envmap/EnvironmentMap.h"
#include "lights/LightSampling.h"
#include "sampling/Pcg32.h"
#include "sampling/Warp.h"

using namespace envgi;

namespace {

Image skyWithSun(int w, int h) {
  Image img(w, h);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) img.set(x, y, Color(y < h / 2 ? 0.8f : 0.1f, 0.5f, 0.4f));
  img.set(w / 3, h / 5, Color(3000.f));  // a sun above the horizon
  img.set(w / 2, h * 3 / 4, Color(800.f));  // and a bright spot below it
  return img;
}

}  // namespace

TEST(CosineProduct, OctahedralMappingRoundTrips) {
  Pcg32 rng(3);
  for (int i = 0; i < 10000; ++i) {
    Vec3f n = sampleUniformSphere(Vec2f(rng.nextFloat(), rng.nextFloat()));
    Vec2f o = octahedralEncode(n);
    ASSERT_GE(o.x, 0.f);
    ASSERT_LE(o.x, 1.f);
    ASSERT_GE(o.y, 0.f);
    ASSERT_LE(o.y, 1.f);
    Vec3f back = octahedralDecode(o);
    ASSERT_NEAR(dot(n, back), 1.f, 1e-5f) << i;
  }
}

// g(bucket, cell) >= n.w for every normal n in the bucket and direction w in the cell: checked
// on random pairs, on a map whose every cell holds light. g is read back from the density the
// draws use (cell chance = cell power x g / the bucket's total), and every pair above the
// horizon must have a density, which is what keeps the estimator unbiased.
TEST(CosineProduct, BoundIsAtLeastTheCosine) {
  Image img(256, 128);
  std::fill(img.rgb.begin(), img.rgb.end(), 1.f);
  EnvironmentMap env(img, {});
  EnvironmentMapView v = env.view();
  const CosineProductView& p = v.product;
  ASSERT_TRUE(p.valid());
  std::vector<double> cellPower(size_t(p.cells()), 0.0);
  for (int py = 0; py < p.height; ++py)
    for (int px = 0; px < p.width; ++px) cellPower[size_t(p.cellOfPixel(px, py))] += v.dist.condFunc[py * p.width + px];
  Pcg32 rng(11);
  int violations = 0, tight = 0, noDensity = 0;
  const int n = 200000;
  for (int i = 0; i < n; ++i) {
    Vec3f nl = sampleUniformSphere(Vec2f(rng.nextFloat(), rng.nextFloat()));
    Vec2f uv(rng.nextFloat(), rng.nextFloat());
    Vec3f w = EnvironmentMapView::uvToDir(uv);
    int px = clampi(int(uv.x * p.width), 0, p.width - 1), py = clampi(int(uv.y * p.height), 0, p.height - 1);
    int k = p.bucket(nl), c = p.cellOfPixel(px, py);
    ASSERT_GT(cellPower[size_t(c)], 0.0);
    const float* cdf = p.bucketCdf + size_t(k) * (p.cells() + 1);
    double g = double(cdf[c + 1] - cdf[c]) * p.bucketInt[k] * p.cells() / cellPower[size_t(c)];
    float cosine = dot(nl, w);
    // Read back through the cdf's float steps, g carries rounding: one of these 200000 pairs
    // reads between 1e-5 and 2e-5 below its cosine. The stored weights were checked to 1e-5.
    if (g < cosine - 5e-5) ++violations;
    if (cosine > 0.f && g < cosine + 0.5) ++tight;
    if (cosine > 0.f && !(p.pdf(uv, nl) > 0.f)) ++noDensity;
  }
  EXPECT_EQ(violations, 0);
  EXPECT_EQ(noDensity, 0);
  // ... and it is a useful bound, not 1 everywhere: most pairs above the horizon sit within 0.5.
  EXPECT_GT(tight, n / 2 * 9 / 10);
}

// pdf() gives the density sample() reports, to the bit, for the same direction.
TEST(CosineProduct, PdfOfADrawEqualsItsDensity) {
  EnvironmentMap env(skyWithSun(96, 48), {});
  const CosineProductView& p = env.view().product;
  ASSERT_TRUE(p.valid());
  Pcg32 rng(23);
  int drawn = 0;
  for (int i = 0; i < 20000; ++i) {
    Vec3f nl = sampleUniformSphere(Vec2f(rng.nextFloat(), rng.nextFloat()));
    Vec2f uv;
    float pdf;
    if (!p.sample(Vec2f(rng.nextFloat(), rng.nextFloat()), nl, &uv, &pdf)) continue;
    ++drawn;
    ASSERT_GT(pdf, 0.f);
    ASSERT_EQ(p.pdf(uv, nl), pdf) << i;
  }
  EXPECT_GT(drawn, 19000);
}

// Draws at the very top of a cell's and a pixel's cdf steps, where (px + r) / width rounds
// onto the next pixel's edge unless kept inside: pdf() still finds the drawn pixel, with the
// drawn density to the bit (a map width that is not a power of two included).
TEST(CosineProduct, DrawsAtTheTopOfAStepStayInTheirPixel) {
  for (int width : {96, 101}) {
    EnvironmentMap env(skyWithSun(width, 48), {});
    const CosineProductView& p = env.view().product;
    ASSERT_TRUE(p.valid());
    Pcg32 rng(29);
    int checked = 0;
    for (int i = 0; i < 20000; ++i) {
      Vec3f nl = sampleUniformSphere(Vec2f(rng.nextFloat(), rng.nextFloat()));
      int k = p.bucket(nl);
      if (!(p.bucketInt[k] > 0.f)) continue;
      const float* cdf = p.bucketCdf + size_t(k) * (p.cells() + 1);
      int c = findIntervalGuided(cdf, rng.nextFloat(), p.bucketGuide + size_t(k) * (p.bucketGuideSize + 1),
                                 p.bucketGuideSize);
      int cx = c % p.cellsX, cy = c / p.cellsX;
      int pixels = (p.cellX0(cx + 1) - p.cellX0(cx)) * (p.cellY0(cy + 1) - p.cellY0(cy));
      const float* pc = p.cellCdf + p.cellCdfStart[c];
      int j = int(rng.nextFloat() * float(pixels));
      if (!(cdf[c + 1] > cdf[c]) || !(pc[j + 1] > pc[j])) continue;
      Vec2f u(std::nextafter(cdf[c + 1], 0.f), std::nextafter(pc[j + 1], 0.f)), uv;
      float pdf;
      if (!p.sample(u, nl, &uv, &pdf)) continue;
      ++checked;
      ASSERT_EQ(p.pdf(uv, nl), pdf) << "width " << width << " draw " << i << " uv " << uv.x * width << "," << uv.y * 48;
    }
    EXPECT_GT(checked, 10000);
  }
}

// Each cell's pixel cdf ends at 1, and cellOfPixel inverts the cells' pixel ranges, also for a
// map whose size is not a multiple of the cell grid; the tables the draws read agree with both.
TEST(CosineProduct, CellsPartitionAnOddSizedMap) {
  Image img(101, 47);
  for (int y = 0; y < 47; ++y)
    for (int x = 0; x < 101; ++x) img.set(x, y, Color(1.f + float((x * 7 + y * 3) % 5)));
  EnvironmentMap env(img, {});
  const CosineProductView& p = env.view().product;
  ASSERT_TRUE(p.valid());
  std::vector<int> seen(size_t(p.cells()), 0);
  for (int cy = 0; cy < p.cellsY; ++cy)
    for (int cx = 0; cx < p.cellsX; ++cx)
      for (int y = p.cellY0(cy); y < p.cellY0(cy + 1); ++y)
        for (int x = p.cellX0(cx); x < p.cellX0(cx + 1); ++x) {
          ASSERT_EQ(p.cellOfPixel(x, y), cy * p.cellsX + cx) << x << "," << y;
          ASSERT_EQ(p.rowCell[y] * p.cellsX + p.columnCell[x], cy * p.cellsX + cx) << x << "," << y;
          ++seen[size_t(cy * p.cellsX + cx)];
        }
  for (int cx = 0; cx <= p.cellsX; ++cx) ASSERT_EQ(p.cellStartX[cx], p.cellX0(cx));
  for (int cy = 0; cy <= p.cellsY; ++cy) ASSERT_EQ(p.cellStartY[cy], p.cellY0(cy));
  int total = 0;
  for (int c = 0; c < p.cells(); ++c) {
    ASSERT_GT(seen[size_t(c)], 0);
    total += seen[size_t(c)];
    EXPECT_FLOAT_EQ(p.cellCdf[p.cellCdfStart[c] + seen[size_t(c)]], 1.f);
  }
  EXPECT_EQ(total, 101 * 47);
}

// Irradiance E(n) = integral of L max(0, n.w): the product strategy's estimate has the same
// mean as Algorithm 1's, and less than 0.6 of its variance, for normals all round the sphere
// (measured: 0.15 to 0.53; the sun's own share of the variance is what neither removes).
TEST(CosineProduct, IrradianceUnbiasedWithLessVariance) {
  EnvironmentMapOptions o;
  o.toWorld = rotate(Vec3f(0.3f, 1.f, 0.2f), 25.f);
  EnvironmentMap env(skyWithSun(128, 64), o);
  EnvironmentMapView v = env.view();
  const Vec3f normals[] = {Vec3f(0, 1, 0), Vec3f(0, -1, 0), normalize(Vec3f(1, 0.2f, 0.3f)),
                           normalize(Vec3f(-0.4f, -0.3f, 0.8f))};
  for (Vec3f n : normals) {
    double mean[2], var[2];
    int s = 0;
    for (EnvStrategy strategy : {EnvStrategy::Importance, EnvStrategy::Product}) {
      Pcg32 rng(21);
      const int count = 200000;
      double sum = 0.0, sum2 = 0.0;
      for (int i = 0; i < count; ++i) {
        EnvSample es = v.sample(strategy, Vec2f(rng.nextFloat(), rng.nextFloat()), n);
        double f = es.pdf > 0.f ? luminance(es.radiance) * std::max(0.f, dot(n, es.dir)) / es.pdf : 0.0;
        sum += f;
        sum2 += f * f;
      }
      mean[s] = sum / count;
      var[s] = std::max(0.0, sum2 / count - mean[s] * mean[s]);
      ++s;
    }
    double se = std::sqrt((var[0] + var[1]) / 200000.0);
    EXPECT_NEAR(mean[1], mean[0], 5.0 * se) << "normal " << n.x << "," << n.y << "," << n.z;
    EXPECT_LT(var[1], 0.6 * var[0]) << "normal " << n.x << "," << n.y << "," << n.z;
  }
}

// A zero axis (a BSDF that transmits) gets Algorithm 1's density over the whole sphere.
TEST(CosineProduct, ZeroAxisIsTheWholeSphere) {
  EnvironmentMap env(skyWithSun(64, 32), {});
  EnvironmentMapView v = env.view();
  Pcg32 rng(5);
  for (int i = 0; i < 1000; ++i) {
    Vec2f u(rng.nextFloat(), rng.nextFloat());
    EnvSample a = v.sample(EnvStrategy::Product, u, Vec3f(0.f)), b = v.sample(EnvStrategy::Importance, u);
    ASSERT_EQ(a.uv.x, b.uv.x);
    ASSERT_EQ(a.uv.y, b.uv.y);
    ASSERT_EQ(v.pdf(EnvStrategy::Product, a.dir, Vec3f(0.f)), v.pdf(EnvStrategy::Importance, a.dir));
  }
}

// The axis the integrators hand to cosine and product: the shading normal on the viewer's side
// for a BSDF that only reflects, the zero axis (the whole sphere) for one that transmits.
TEST(CosineProduct, SamplingAxisFollowsTheViewerAndTransmission) {
  SurfaceInteraction si;
  si.shading = Frame::fromNormal(normalize(Vec3f(0.2f, 1.f, 0.1f)));
  Bsdf diffuse, glass;
  glass.type = BsdfType::RoughDielectric;
  Vec3f above(0.f, 1.f, 0.f), below(0.f, -1.f, 0.f);
  Vec3f a = envSamplingAxis(si, above, diffuse), b = envSamplingAxis(si, below, diffuse);
  EXPECT_NEAR(dot(a, si.shading.n), 1.f, 1e-6f);
  EXPECT_NEAR(dot(b, si.shading.n), -1.f, 1e-6f);
  for (BsdfType t : {BsdfType::RoughDielectric, BsdfType::Dielectric, BsdfType::ThinDielectric}) {
    glass.type = t;
    EXPECT_EQ(lengthSq(envSamplingAxis(si, above, glass)), 0.f) << int(t);
  }
}


// The prefetch before a round's escapes (the CPU's escape stage, HostStages.h) reads the product's small tables
// to find its addresses: at the poles, across the seam and for a zero axis it stays inside
// them (the sanitizer build checks the reads), and the lookup after it is the same to the bit.
TEST(CosineProduct, PrefetchingAnEscapeReadsInsideTheTables) {
  EnvironmentMap env(skyWithSun(96, 48), {});
  EnvironmentMapView v = env.view();
  const Vec3f dirs[] = {{0.f, 1.f, 0.f}, {0.f, -1.f, 0.f}, {0.f, 0.f, -1.f}, {-1e-7f, 0.f, -1.f}, {1e-7f, 0.3f, -1.f},
                        {0.3f, -0.9f, 0.1f}};
  const Vec3f axes[] = {{0.f, 1.f, 0.f}, {0.f, 0.f, 0.f}, {0.f, -1.f, 0.f}, {1.f, 0.f, 0.f}};
  for (Vec3f d : dirs)
    for (Vec3f n : axes)
      for (EnvStrategy s : {EnvStrategy::Product, EnvStrategy::Importance}) {
        float before, after;
        Color a = v.evalWithPdf(s, d, n, &before);
        v.prefetchEvalWithPdf(s, EnvironmentMapView::dirToUV(v.toLocalUnnormalized(d)), n);
        Color b = v.evalWithPdf(s, d, n, &after);
        ASSERT_EQ(before, after);
        ASSERT_EQ(a.x, b.x);
        const Vec2f uv = EnvironmentMapView::dirToUV(v.toLocalUnnormalized(d));
        if (lengthSq(n) > 0.f) {
          const CosineProductView::Step st = v.product.stepAt(uv, v.toLocalUnnormalized(n));
          ASSERT_GE(st.k, 0);
          ASSERT_LT(st.c, v.product.cells());
          ASSERT_EQ(v.product.pdfUV(st.k, st.c, st.j), v.product.pdf(uv, v.toLocalUnnormalized(n)));
        }
      }
}

// The draw taken a level at a time (ProductDescent) reaches the pixel sample() draws for the same
// u and normal, in odd-sized maps too; it gives up only where sample() draws nothing (a bucket
// that sees no light). Ended there (descentEnd), it is sample()'s draw to the bit, and the map's
// sample from it is EnvironmentMapView::sample's.
TEST(CosineProduct, ADrawTakenLevelByLevelReachesTheDrawnPixel) {
  Image below(64, 32);  // lit from below the horizon only
  for (int y = 0; y < 32; ++y)
    for (int x = 0; x < 64; ++x) below.set(x, y, Color(y < 16 ? 0.f : 1.f));
  const Image maps[] = {skyWithSun(96, 48), skyWithSun(101, 47), below};
  for (const Image& img : maps) {
    EnvironmentMap env(img, {});
    const CosineProductView& p = env.view().product;
    ASSERT_TRUE(p.valid());
    Pcg32 rng(31);
    int reached = 0;
    for (int i = 0; i < 20000; ++i) {
      const Vec3f nl = sampleUniformSphere(Vec2f(rng.nextFloat(), rng.nextFloat()));
      const Vec2f u(rng.nextFloat(), rng.nextFloat());
      ProductDescent a;
      p.descend0(u, nl, &a);
      p.descend1(&a);
      p.descend2(&a);
      p.descend3(&a);
      int px = -1, py = -1;
      const bool walked = p.descendToPixel(&a, &px, &py);
      Vec2f uv;
      float pdf;
      const bool drawn = p.sample(u, nl, &uv, &pdf);
      ASSERT_TRUE(walked || !drawn) << i;
      Vec2f endUV;
      float endPdf;
      ASSERT_EQ(p.descentEnd(a, &endUV, &endPdf), drawn) << i;
      if (!drawn) continue;
      ASSERT_EQ(endUV.x, uv.x) << i;
      ASSERT_EQ(endUV.y, uv.y) << i;
      ASSERT_EQ(endPdf, pdf) << i;
      // The map's sample from the descent's end is sample()'s, for a normal whose local form is nl.
      const EnvironmentMapView& v = env.view();
      const Vec3f n = v.fromLocal(nl);
      if (sameBits(v.toLocalUnnormalized(n), nl)) {
        const EnvSample es = v.sample(EnvStrategy::Product, u, n), fromEnd = v.productSample(endUV, endPdf);
        ASSERT_TRUE(sameBits(es.dir, fromEnd.dir) && es.pdf == fromEnd.pdf && sameBits(es.radiance, fromEnd.radiance))
            << i;
      }
      ++reached;
      ASSERT_EQ(px, std::min(int(uv.x * float(img.width)), img.width - 1)) << i;
      ASSERT_EQ(py, std::min(int(uv.y * float(img.height)), img.height - 1)) << i;
    }
    EXPECT_GT(reached, 9000) << img.width << " x " << img.height;
  }
}
