// Photon emission and maps: energy bookkeeping in a closed box, the kd-tree estimate of a
// known flux density, the hashed grid, and black maps.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "integrators/PhotonIntegrator.h"
#include "integrators/Sppm.h"
#include "materials/BsdfFactory.h"
#include "photon/HashGrid.h"
#include "photon/PhotonMap.h"
#include "render/PhotonShooter.h"
#include "sampling/Pcg32.h"
#include "support/TestScenes.h"
#include "scene/NameTables.h"

using namespace envgi;

namespace {

// A closed box [-1,1]^3 facing inwards, albedo rho, lit by a tiny black emissive sphere.
std::unique_ptr<Scene> closedBox(float rho) {
  auto s = std::make_unique<Scene>();
  Bsdf wall;
  wall.reflectance = Color(rho);
  Bsdf black;
  black.reflectance = Color(0.f);
  s->bsdfs = {wall, black};
  TriangleMesh cube = makeCube();
  for (size_t i = 0; i < cube.indices.size(); i += 3) std::swap(cube.indices[i + 1], cube.indices[i + 2]);
  for (Vec3f& n : cube.normals) n = -n;
  s->meshes.push_back(cube);
  s->shapes.push_back({false, 0, 0, false, Color(0.f)});
  s->spheres.push_back({Vec3f(0.f), 0.01f, false});
  s->shapes.push_back({true, 0, 1, true, Color(1.f)});
  s->camera.width = s->camera.height = 8;
  s->camera.tanHalfX = s->camera.tanHalfY = 0.5f;
  s->finalize();
  return s;
}

// No geometry, one diffuse BSDF (index 0) of albedo rho: enough for PhotonMap::estimate.
void withOneDiffuseBsdf(Scene& s, float rho) {
  Bsdf d;
  d.reflectance = Color(rho);
  s.bsdfs = {d};
  s.finalize();
}

}  // namespace

// Stored power = emitted power x (rho + rho^2 + ...) = Phi rho / (1 - rho): the first hit is
// not stored (direct light is the renderer's), every later arrival is.
TEST(PhotonShooting, ClosedBoxEnergyBalance) {
  for (float rho : {0.3f, 0.6f}) {
    auto scene = closedBox(rho);
    EmbreeAccel accel(*scene);
    PhotonShootSettings ps;
    ps.globalPhotons = 200000;
    ps.causticPhotons = 0;
    ps.maxDepth = 64;
    ps.progress = false;
    PhotonMap global, caustic;
    PhotonShootStats st;
    shootPhotons(*scene, accel, ps, &global, &caustic, &st);
    EXPECT_EQ(caustic.size(), 0u);
    double stored = 0.0;
    for (const Photon& p : global.photons()) stored += p.power.y;
    double phi = kPi * 4.0 * kPi * 0.01 * 0.01;  // Le pi A, one-sided
    double expected = phi * rho / (1.0 - rho);
    EXPECT_NEAR(stored, expected, 0.02 * expected) << "rho " << rho;
  }
}

// Photons spread uniformly over a plane with flux density E give L = rho/pi E on a diffuse
// surface (Eq. 12).
TEST(PhotonMapEstimate, UniformDensityGivesDiffuseRadiance) {
  Scene s;
  withOneDiffuseBsdf(s, 0.5f);
  std::vector<Photon> ph;
  Pcg32 rng(2);
  const int n = 200000;
  const float E = 3.f, area = 4.f;  // the plane [-1,1]^2 at z = 0
  for (int i = 0; i < n; ++i) {
    Vec3f wi = sampleCosineHemisphere({rng.nextFloat(), rng.nextFloat()});
    // Named draws: the order of a constructor's arguments is the compiler's choice (gcc and
    // clang differ), and with it the photons.
    float x = 2.f * rng.nextFloat() - 1.f, y = 2.f * rng.nextFloat() - 1.f;
    ph.push_back({Vec3f(x, y, 0.f), wi, Vec3f(0, 0, 1), Color(E * area / n)});
  }
  PhotonMap map;
  map.build(ph);
  SurfaceInteraction si;
  si.p = Vec3f(0.1f, -0.2f, 0.f);
  si.ng = Vec3f(0, 0, 1);
  si.shading = Frame::fromNormal(si.ng);
  si.bsdf = 0;
  for (bool cone : {false, true}) {
    PhotonLookup q;
    q.k = 200;
    q.maxRadius = 0.5f;
    q.coneFilter = cone;
    Color L = map.estimate(s.view(), si, Vec3f(0, 0, 1), q);
    // One lookup of k photons has relative noise 1/sqrt(k): three of those is its tolerance.
    EXPECT_NEAR(L.x, 0.5f / kPi * E, 3.f / std::sqrt(float(q.k)) * 0.5f / kPi * E) << "cone " << cone;
    // One lookup has 1/sqrt(k) = 7% noise; 400 lookups over the plane's inside average it
    // down, so a normalisation error of a few percent shows.
    double mean = 0.0;
    Pcg32 pr(77);
    const int lookups = 400;
    for (int i = 0; i < lookups; ++i) {
      SurfaceInteraction sj = si;
      float x = 1.8f * pr.nextFloat() - 0.9f, y = 1.8f * pr.nextFloat() - 0.9f;
      sj.p = Vec3f(x, y, 0.f);
      mean += map.estimate(s.view(), sj, Vec3f(0, 0, 1), q).x / lookups;
    }
    EXPECT_NEAR(mean, 0.5 / kPi * E, 0.015 * 0.5 / kPi * E) << "cone " << cone << ", mean of " << lookups;
  }
  size_t points = map.beginIrradiance(4);
  EXPECT_EQ(points, (map.size() + 3) / 4);
  for (size_t i = 0; i < points; ++i) map.estimateIrradiance(i, 200, 0.5f);
  map.endIrradiance();
  EXPECT_NEAR(map.irradiance(si.p, Vec3f(0, 0, 1)).x, E, 0.1f * E);
  EXPECT_EQ(map.irradiance(si.p, Vec3f(0, 0, -1)).x, 0.f) << "the back side has no irradiance point";
  // The lookup is bounded by the radius each point was estimated over: 100 units away, where no
  // photon arrived, a gather ray finds nothing rather than the plane's irradiance.
  EXPECT_EQ(map.irradiance(Vec3f(100.f, 0.f, 0.f), Vec3f(0, 0, 1)).x, 0.f);
  EXPECT_EQ(map.irradiance(Vec3f(0.f, 0.f, 3.f), Vec3f(0, 0, 1)).x, 0.f);
  EXPECT_GT(map.irradiance(Vec3f(0.99f, 0.f, 0.f), Vec3f(0, 0, 1)).x, 0.f) << "the plane's edge is still covered";
}

// The order the irradiance points are estimated in (PhotonShooter): every point once, neighbours
// next to each other, and the same cache as estimating them in index order.
TEST(PhotonMap, IrradianceOrderKeepsNeighboursTogetherAndChangesNoEstimate) {
  Pcg32 rng(12);
  std::vector<Photon> photons(20000);
  for (Photon& ph : photons) {
    ph.p = Vec3f(rng.nextFloat() * 4 - 2, rng.nextFloat() * 4 - 2, 0.f);  // shot order: all over the plane
    ph.n = ph.wi = Vec3f(0, 0, 1);
    ph.power = Color(rng.nextFloat());
  }
  PhotonMap inOrder, sorted;
  inOrder.build(photons);
  sorted.build(photons);
  const size_t n = inOrder.beginIrradiance(4);
  ASSERT_EQ(sorted.beginIrradiance(4), n);
  const std::vector<uint32_t> order = sorted.irradianceOrder();
  ASSERT_EQ(order.size(), n);
  std::vector<char> seen(n, 0);
  for (uint32_t i : order) {
    ASSERT_LT(i, n);
    EXPECT_FALSE(seen[i]) << i << " twice";
    seen[i] = 1;
  }
  // Consecutive points: in Morton order a few photon spacings apart, in shot order about the
  // plane's mean distance between two random points (about 2).
  auto meanStep = [&](auto at) {
    double sum = 0.0;
    for (size_t j = 1; j < n; ++j) sum += length(photons[4 * at(j)].p - photons[4 * at(j - 1)].p);
    return sum / double(n - 1);
  };
  const double shot = meanStep([](size_t j) { return j; }), morton = meanStep([&](size_t j) { return size_t(order[j]); });
  EXPECT_GT(shot, 1.5);
  EXPECT_LT(morton, 0.1) << "shot order " << shot;
  for (size_t i = 0; i < n; ++i) inOrder.estimateIrradiance(i, 50, 0.5f);
  for (uint32_t i : order) sorted.estimateIrradiance(i, 50, 0.5f);
  inOrder.endIrradiance();
  sorted.endIrradiance();
  for (int t = 0; t < 200; ++t) {
    Vec3f q(rng.nextFloat() * 4 - 2, rng.nextFloat() * 4 - 2, 0.f);
    EXPECT_EQ(inOrder.irradiance(q, Vec3f(0, 0, 1)).x, sorted.irradiance(q, Vec3f(0, 0, 1)).x);
  }
}

// The radiance estimate (Eq. 11-12) reads the k nearest photons within the search radius, and
// the radius is the k-th one's distance, or the search radius where fewer lie within it: against
// a brute-force search, on queries inside two clusters, at their rims, between them and far out
// (where the search, bounded by the radius, must find nothing rather than far photons).
TEST(PhotonMapEstimate, KNearestWithinTheRadiusAsBruteForceFindsThem) {
  Scene s;
  withOneDiffuseBsdf(s, 0.8f);
  Pcg32 rng(21);
  std::vector<Photon> ph(6000);
  for (size_t i = 0; i < ph.size(); ++i) {
    // Two discs of photons on the plane z = 0, a dense one and a sparse one.
    const bool dense = i % 3 != 0;
    const float cx = dense ? 0.f : 3.f, spread = dense ? 0.5f : 1.5f;
    const float x = cx + spread * (2.f * rng.nextFloat() - 1.f), y = spread * (2.f * rng.nextFloat() - 1.f);
    ph[i] = {Vec3f(x, y, 0.f), Vec3f(0, 0, 1), Vec3f(0, 0, 1), Color(1.f + rng.nextFloat())};
  }
  PhotonMap map;
  map.build(ph);
  PhotonLookup q;
  q.k = 40;
  q.maxRadius = 0.12f;
  const float maxR2 = q.maxRadius * q.maxRadius;
  int full = 0, partial = 0, none = 0;
  for (int t = 0; t < 600; ++t) {
    SurfaceInteraction si;
    const float a = rng.nextFloat(), b = rng.nextFloat();
    if (t % 5 < 2) si.p = Vec3f(1.2f * a - 0.6f, 1.2f * b - 0.6f, 0.f);          // the dense disc and its rim
    else if (t % 5 < 4) si.p = Vec3f(3.f + 3.4f * a - 1.7f, 3.4f * b - 1.7f, 0.f);  // the sparse one
    else si.p = Vec3f(50.f + float(t), -20.f * a, 1.f);                           // far from every photon
    si.ng = Vec3f(0, 0, 1);
    si.shading = Frame::fromNormal(si.ng);
    si.bsdf = 0;
    std::vector<std::pair<float, size_t>> byDistance;
    for (size_t i = 0; i < ph.size(); ++i) byDistance.push_back({lengthSq(ph[i].p - si.p), i});
    std::sort(byDistance.begin(), byDistance.end());
    size_t kept = 0;
    while (kept < size_t(q.k) && byDistance[kept].first <= maxR2) ++kept;
    const float r2 = kept < size_t(q.k) ? maxR2 : byDistance[kept - 1].first;
    double expect = 0.0;
    for (size_t j = 0; j < kept; ++j) expect += double(ph[byDistance[j].second].power.x);
    expect *= 0.8 / kPi / (kPi * double(r2));  // f = albedo / pi, over the disc pi r^2
    const float got = map.estimate(s.view(), si, Vec3f(0, 0, 1), q).x;
    ASSERT_NEAR(got, expect, 1e-5 * expect + 1e-30) << "query " << t << " with " << kept << " photons";
    (kept == size_t(q.k) ? full : kept > 0 ? partial : none) += 1;
  }
  EXPECT_GT(full, 100);
  EXPECT_GT(partial, 20);
  EXPECT_GT(none, 60);
}

TEST(HashGrid, FindsEveryPointWithinTheCellSize) {
  Pcg32 rng(4);
  std::vector<Vec3f> pts(5000);
  std::vector<char> valid(pts.size(), 1);
  for (Vec3f& p : pts) p = Vec3f(rng.nextFloat() * 4 - 2, rng.nextFloat() * 4 - 2, rng.nextFloat() * 4 - 2);
  valid[7] = 0;
  const float r = 0.3f;
  HashGrid g;
  g.build(pts, valid, r);
  for (int t = 0; t < 200; ++t) {
    Vec3f q(rng.nextFloat() * 4 - 2, rng.nextFloat() * 4 - 2, rng.nextFloat() * 4 - 2);
    std::vector<int> found, expect;
    g.view().forNeighbours(q, [&](int i) {
      if (lengthSq(pts[size_t(i)] - q) <= r * r) found.push_back(i);
    });
    for (size_t i = 0; i < pts.size(); ++i)
      if (valid[i] && lengthSq(pts[i] - q) <= r * r) expect.push_back(int(i));
    std::sort(found.begin(), found.end());
    ASSERT_EQ(found, expect);
  }
}

// The box query the irradiance cache's levels use: every point within h (half a cell) of the
// query, whichever side of a cell boundary it lies on; far and non-finite queries end at once.
TEST(HashGrid, BoxOfHalfACellFindsEveryPointWithinIt) {
  Pcg32 rng(5);
  std::vector<Vec3f> pts(5000);
  std::vector<char> valid(pts.size(), 1);
  for (Vec3f& p : pts) p = Vec3f(rng.nextFloat() * 4 - 2, rng.nextFloat() * 4 - 2, rng.nextFloat() * 4 - 2);
  const float h = 0.15f;
  HashGrid g;
  g.build(pts, valid, 2.f * h);
  for (int t = 0; t < 300; ++t) {
    Vec3f q(rng.nextFloat() * 4 - 2, rng.nextFloat() * 4 - 2, rng.nextFloat() * 4 - 2);
    if (t % 10 == 0) q = Vec3f(0.3f * float(t / 10), 0.f, -0.3f);  // on cell boundaries
    std::vector<int> found, expect;
    const HashGridView& v = g.view();
    v.forBucketsAround(q, h, [&](int begin, int end) {
      for (int j = begin; j < end; ++j)
        if (lengthSq(pts[size_t(v.items[j])] - q) <= h * h) found.push_back(v.items[j]);
    });
    for (size_t i = 0; i < pts.size(); ++i)
      if (lengthSq(pts[i] - q) <= h * h) expect.push_back(int(i));
    std::sort(found.begin(), found.end());
    found.erase(std::unique(found.begin(), found.end()), found.end());
    ASSERT_EQ(found, expect) << "query " << t;
  }
  for (Vec3f q : {Vec3f(1e30f, 0.f, 0.f), Vec3f(NAN, 0.f, 0.f), Vec3f(-INFINITY, 1.f, 2.f)}) {
    int visits = 0;
    g.view().forBucketsAround(q, h, [&](int begin, int end) { visits += end - begin; });
    EXPECT_LT(visits, 5000) << "at most 27 buckets' points";
  }
}

// The GPU builds the grid by radix-sorting (key, index) pairs and finding the bucket starts per
// sorted position; the same steps here, with a stable sort, give the CPU's counting sort.
TEST(HashGrid, SortedKeysGiveTheCountingSortsArrays) {
  Pcg32 rng(9);
  std::vector<Vec3f> pts(3000);
  std::vector<char> valid(pts.size(), 1);
  for (Vec3f& p : pts) p = Vec3f(rng.nextFloat() * 3, rng.nextFloat() * 3, rng.nextFloat() * 3);
  for (size_t i = 0; i < pts.size(); i += 7) valid[i] = 0;
  HashGrid g;
  g.build(pts, valid, 0.2f);
  const HashGridView& v = g.view();
  std::vector<std::pair<int, int>> pairs;
  for (size_t i = 0; i < pts.size(); ++i) pairs.push_back({v.key(pts[i], valid[i] != 0), int(i)});
  std::stable_sort(pairs.begin(), pairs.end(), [](auto& a, auto& b) { return a.first < b.first; });
  std::vector<int> keys, start(size_t(v.tableSize) + 1, -1);
  for (auto& pr : pairs) keys.push_back(pr.first);
  int n = int(keys.size());
  for (int i = 0; i <= n; ++i) hashGridBucketStarts(keys.data(), n, v.tableSize, i, start.data());
  for (int b = 0; b <= v.tableSize; ++b) ASSERT_EQ(start[size_t(b)], v.bucketStart[b]) << "bucket " << b;
  ASSERT_EQ(start.back(), int(pts.size() - (pts.size() + 6) / 7));
  for (int i = 0; i < start.back(); ++i) ASSERT_EQ(pairs[size_t(i)].second, v.items[i]);
}

// The irradiance lookup (CPU and GPU alike) is the nearest point facing the same way whose own
// radius covers the query: against a brute-force search over points of mixed radii and normals.
TEST(IrradianceCache, NearestCoveringPointFacingTheSameWay) {
  Pcg32 rng(11);
  std::vector<IrradiancePoint> pts(4000);
  for (size_t i = 0; i < pts.size(); ++i) {
    IrradiancePoint& ip = pts[i];
    ip.p = Vec3f(rng.nextFloat() * 2, rng.nextFloat() * 2, rng.nextFloat() * 0.1f);
    ip.n = rng.nextFloat() < 0.8f ? Vec3f(0, 0, 1) : Vec3f(0, 0, -1);
    // Radii from 0.002 to 0.2, spread evenly in their logarithm: the cache's levels of radius
    // all hold points.
    float r = 0.002f * std::pow(100.f, rng.nextFloat());
    ip.r2 = r * r;
    ip.e = Color(float(i));
  }
  IrradianceCache cache;
  cache.build(pts);
  EXPECT_EQ(cache.view().levelCount, kIrradianceLevels);
  int hits = 0;
  for (int t = 0; t < 3000; ++t) {
    Vec3f q(rng.nextFloat() * 2, rng.nextFloat() * 2, rng.nextFloat() * 0.1f);
    Vec3f n = t % 3 ? Vec3f(0, 0, 1) : Vec3f(0, 0, -1);
    float best = INFINITY;
    Color expect(0.f);
    for (const IrradiancePoint& ip : pts) {
      float d2 = lengthSq(ip.p - q);
      if (d2 <= ip.r2 && d2 < best && dot(ip.n, n) > kSameSurfaceCos) {
        best = d2;
        expect = ip.e;
      }
    }
    hits += best < INFINITY;
    ASSERT_EQ(cache.view().irradiance(q, n).x, expect.x) << "query " << t;
  }
  EXPECT_GT(hits, 1000);
  EXPECT_LT(hits, 3000);
}

// Points at one place, on different levels (the finer one, read last, has the lower index):
// the lookup answers with the lower index, whatever order its levels and buckets come in.
TEST(IrradianceCache, TiesGoToTheLowerIndexAcrossLevels) {
  std::vector<IrradiancePoint> pts(2);
  pts[0] = {Vec3f(1.f, 2.f, 3.f), Vec3f(0, 0, 1), Color(10.f), 0.05f * 0.05f};
  pts[1] = {Vec3f(1.f, 2.f, 3.f), Vec3f(0, 0, 1), Color(20.f), 0.5f * 0.5f};
  IrradianceCache cache;
  cache.build(pts);
  ASSERT_EQ(cache.view().levelCount, 2);
  EXPECT_EQ(cache.view().irradiance(Vec3f(1.01f, 2.f, 3.f), Vec3f(0, 0, 1)).x, 10.f);
  EXPECT_EQ(cache.view().irradiance(Vec3f(1.2f, 2.f, 3.f), Vec3f(0, 0, 1)).x, 20.f) << "only the wide one covers";
}

// An all-black map is a light of zero power: no photons, a black image, no NaN.
TEST(PhotonIntegrators, BlackMapShootsNothingAndRendersBlack) {
  Bsdf b;
  auto scene = test::furnaceScene(b, 16, 4);
  scene->env = std::make_unique<EnvironmentMap>(Image(16, 8), EnvironmentMapOptions{});
  scene->finalize();
  EmbreeAccel accel(*scene);
  PhotonShootSettings ps;
  ps.progress = false;
  PhotonMap g, c;
  shootPhotons(*scene, accel, ps, &g, &c, nullptr);
  EXPECT_EQ(g.size() + c.size(), 0u);
  for (const char* type : {"photon", "sppm"}) {
    scene->integrator.type = findIntegrator(type);
    scene->integrator.sppm.passes = 3;
    scene->integrator.sppm.photonCount = 1000;
    RenderOptions o;
    o.progress = false;
    RenderStats st;
    Image img = render(*scene, accel, o, &st);
    for (float v : img.rgb) ASSERT_EQ(v, 0.f) << type;
  }
}

// With MIS compensation on, photons still leave the map by its plain luminance: directions
// darker than the mean emit too. mean(L/pdf) over emitted photons is the map's power, per
// channel, within 5 sigma; and `direct` refuses a compensated density with no BSDF samples.
TEST(PhotonEmission, CompensatedMapStillEmitsEverywhere) {
  Image sky(64, 32);
  for (int y = 0; y < 32; ++y)
    for (int x = 0; x < 64; ++x)
      sky.set(x, y, Color(0.2f + 0.01f * x, 0.3f, (x == 40 && y == 9) ? 400.f : 0.1f));
  Bsdf floor;
  auto scene = test::sphereOnFloor(floor, floor, 2.f, Image(sky), Vec3f(0, 2, 5), Vec3f(0, 0.5f, 0), 8, 40.f);
  EnvironmentMapOptions o;
  o.misCompensation = true;
  scene->env = std::make_unique<EnvironmentMap>(std::move(sky), o);
  scene->finalize();
  Color power = scene->env->stats().power;
  PhotonEmitter em = makePhotonEmitter(*scene);
  const SceneView& sc = scene->view();
  const int n = 400000;
  double sum[3] = {0, 0, 0}, sumSq[3] = {0, 0, 0};
  Sampler smp;
  for (int i = 0; i < n; ++i) {
    smp.start(uint64_t(i), 0);
    Ray r;
    Color pw;
    Color v(0.f);
    if (em.emit(sc, smp, &r, &pw)) v = pw / (kPi * em.radius * em.radius);
    for (int k = 0; k < 3; ++k) {
      sum[k] += v[k];
      sumSq[k] += double(v[k]) * v[k];
    }
  }
  for (int k = 0; k < 3; ++k) {
    double mean = sum[k] / n, se = std::sqrt(std::max(0.0, sumSq[k] / n - mean * mean) / n);
    EXPECT_NEAR(mean, power[k], 5.0 * se + 1e-6) << "channel " << k;
  }
  scene->integrator.type = IntegratorType::Direct;
  scene->integrator.env.strategy = "importance";
  EmbreeAccel accel(*scene);
  RenderOptions ro;
  ro.progress = false;
  EXPECT_THROW(render(*scene, accel, ro, nullptr), std::runtime_error);
  scene->integrator.env.strategy = "mis";
  EXPECT_NO_THROW(render(*scene, accel, ro, nullptr));
}

// The final gather's stand-in albedo for plastic is the base's true albedo towards the normal
// under uniform light (a quadrature of eval), not above it: white plastic creates no energy.
TEST(PhotonIntegrators, PlasticGatherAlbedoIsTheBaseAlbedo) {
  for (float ior : {1.3f, 1.5f, 1.9f}) {
    Bsdf b;
    b.type = BsdfType::Plastic;
    b.reflectance = Color(1.f);
    b.ior = ior;
    finishPlastic(b);
    Pcg32 rng(8);
    const int n = 400000;
    double sum = 0.0;
    for (int i = 0; i < n; ++i) {
      Vec3f wi = sampleUniformHemisphere(Vec2f(rng.nextFloat(), rng.nextFloat()));
      sum += bsdfEval(b, Vec3f(0, 0, 1), wi).x * 2.0 * kPi;  // eval carries cos(wi)
    }
    double albedo = sum / n;
    EXPECT_NEAR(diffuseAlbedo(b).x, albedo, 0.005 * albedo) << "ior " << ior;
    EXPECT_LT(albedo, 1.0);
  }
}

// A closed box whose inward walls all emit Le and reflect rho: radiance is Le / (1 - rho)
// everywhere. path, sppm (photons from the area lights) and photon (final gather) all give it.
TEST(PhotonIntegrators, EmissiveClosedBoxGivesLeOverOneMinusRho) {
  const float rho = 0.5f, Le = 1.f;
  auto s = closedBox(rho);
  s->spheres.clear();
  s->shapes.pop_back();
  s->shapes[0].emissive = true;
  s->shapes[0].radiance = Color(Le);
  s->camera.width = s->camera.height = 16;
  s->camera.tanHalfX = s->camera.tanHalfY = 0.8f;
  s->camera.filter = makeFilter(FilterType::Box);
  s->finalize();
  EmbreeAccel accel(*s);
  const double expected = Le / (1.0 - rho);
  struct Run {
    const char* type;
    int spp;
    double tolerance;
  };
  for (Run r : {Run{"path", 64, 0.01}, Run{"sppm", 64, 0.02}, Run{"photon", 8, 0.03}}) {
    s->integrator = IntegratorSettings{};
    s->integrator.type = findIntegrator(r.type);
    s->integrator.sppm.photonCount = 20000;
    s->integrator.photon.globalPhotons = 100000;
    s->integrator.photon.causticPhotons = 1000;
    s->integrator.photon.gatherSamples = 8;
    s->finalize();
    RenderOptions o;
    o.progress = false;
    o.spp = r.spp;
    RenderStats st;
    Image img = render(*s, accel, o, &st);
    double mean = 0.0;
    for (int y = 0; y < 16; ++y)
      for (int x = 0; x < 16; ++x) mean += img.at(x, y).y / 256.0;
    std::printf("%s: %.4f (expected %.4f)\n", r.type, mean, expected);
    EXPECT_NEAR(mean, expected, r.tolerance * expected) << r.type;
  }
}

// Photons from a constant sky of radiance L onto a plane of area A facing up: the power that
// arrives is the irradiance pi L times A (photons leave the map by Algorithm 1's density).
TEST(PhotonEmission, ConstantSkyDeliversPiLAToAPlane) {
  Bsdf floor;
  Image sky(32, 16);
  for (float& v : sky.rgb) v = 2.f;
  auto s = test::sphereOnFloor(floor, floor, 1.f, std::move(sky), Vec3f(0, 2, 5), Vec3f(0, 0, 0), 8, 40.f);
  s->spheres.clear();
  s->shapes.pop_back();
  s->finalize();
  PhotonEmitter em = makePhotonEmitter(*s);
  const SceneView& sc = s->view();
  const int n = 1000000;
  double arrived = 0.0;
  Sampler smp;
  for (int i = 0; i < n; ++i) {
    smp.start(uint64_t(i), 0);
    Ray r;
    Color pw;
    if (!em.emit(sc, smp, &r, &pw) || r.d.y >= 0.f) continue;
    float t = -r.o.y / r.d.y;  // the plane y = 0, [-1, 1]^2
    Vec3f p = r.o + r.d * t;
    if (t > 0.f && std::fabs(p.x) <= 1.f && std::fabs(p.z) <= 1.f) arrived += pw.y / n;
  }
  double expected = kPi * 2.0 * 4.0;
  std::printf("arrived %.4f (expected %.4f)\n", arrived, expected);
  EXPECT_NEAR(arrived, expected, 0.02 * expected);
}

// Caustic photons aimed at two glass balls whose disks overlap from many directions: through
// each ball pass, from a constant sky of radiance L, the rays of every unaimed photon, with
// flux L 4 pi pi r^2; from a sun of irradiance E, E pi r^2; from a point light of intensity I,
// I times the solid angle the ball subtends; from an area light of radiance L facing down, L
// times the cone's projected solid angle summed over the light, pi r^2 / d^2 cos(axis, n) dA
// (every cone lies in front of the light). Each aimed map or sun photon leaves beyond the
// scene's bounding sphere, so nothing on its line is skipped.
TEST(PhotonEmission, AimedPhotonsCarryTheFluxThroughEachBall) {
  Bsdf floor, glass;
  glass.type = BsdfType::Dielectric;
  glass.ior = 1.5f;
  Image sky(32, 16);
  for (float& v : sky.rgb) v = 2.f;
  auto s = test::sphereOnFloor(floor, glass, 8.f, std::move(sky), Vec3f(0, 2, 5), Vec3f(0, 0, 0), 8, 40.f);
  s->spheres.push_back({Vec3f(1.5f, 1.3f, 0.4f), 0.7f, false});
  s->shapes.push_back({true, 1, 1, false, Color(0.f)});
  s->finalize();
  const Sphere balls[2] = {s->spheres[0], s->spheres[1]};
  const Vec3f bulb(-1.2f, 3.5f, 0.6f);
  // The area light: a 1 x 0.6 rectangle at y = 3.5 about (-1, 0.4), facing down.
  const Vec3f panel(-1.f, 3.5f, 0.4f);
  const float halfX = 0.5f, halfZ = 0.3f, panelL = 2.5f;
  for (const char* light : {"sky", "sun", "point", "area"}) {
    const std::string kind = light;
    if (kind == "area") {
      s->deltaLights.clear();
      TriangleMesh m = makeRectangle();  // [-1, 1]^2 at z = 0 facing +z: (x, y) to (x, z) faces -y
      for (Vec3f& p : m.positions) p = panel + Vec3f(p.x * halfX, 0.f, p.y * halfZ);
      m.normals.clear();
      s->meshes.push_back(m);
      s->bsdfs.push_back(Bsdf{});
      s->shapes.push_back({false, s->meshes.size() - 1, int(s->bsdfs.size()) - 1, true, Color(panelL)});
      s->finalize();
    } else if (kind != "sky") {
      s->env.reset();
      DeltaLight l;
      if (kind == "sun") {
        l.v = normalize(Vec3f(0.6f, -1.f, 0.1f));  // along the line of centres, partly: overlaps
        l.value = Color(3.f);
      } else {
        l.v = bulb;  // up and to the side: the balls' cones overlap
        l.value = Color(4.f);
        l.point = true;
      }
      s->deltaLights = {l};
      s->finalize();
    }
    PhotonEmitter em = makePhotonEmitter(*s, true);
    ASSERT_EQ(em.targetCount, 2) << kind;
    const SceneView& sc = s->view();
    const int n = 400000;
    double flux[2] = {0.0, 0.0}, both = 0.0;
    int upstream = 0, emitted = 0;
    Sampler smp;
    for (int i = 0; i < n; ++i) {
      smp.start(uint64_t(i), 0);
      Ray r;
      Color pw;
      if (!em.emit(sc, smp, &r, &pw, true)) continue;
      ++emitted;
      upstream += dot(r.o - em.center, -r.d) >= em.radius;
      bool through[2];
      for (int k = 0; k < 2; ++k) {
        Vec3f v = balls[k].center - r.o;
        through[k] = dot(v, r.d) > 0.f && lengthSq(v - r.d * dot(v, r.d)) < balls[k].radius * balls[k].radius;
        if (through[k]) flux[k] += pw.y / n;
      }
      if (through[0] && through[1]) both += pw.y / n;
    }
    if (kind == "sky" || kind == "sun") {
      EXPECT_EQ(upstream, emitted) << kind;
    }
    EXPECT_GT(both, 0.02 * flux[1]) << kind << ": the balls should overlap from some directions";
    for (int k = 0; k < 2; ++k) {
      double r2 = double(balls[k].radius) * balls[k].radius;
      double d2 = double(lengthSq(balls[k].center - bulb));
      double expected = kind == "sky"   ? 2.0 * 4.0 * kPi * kPi * r2
                        : kind == "sun" ? 3.0 * kPi * r2
                                        : 4.0 * 2.0 * kPi * (1.0 - std::sqrt(1.0 - r2 / d2));
      if (kind == "area") {
        // Midpoint rule over the panel, 200 x 120 cells.
        const int nx = 200, nz = 120;
        const double dA = (2.0 * halfX / nx) * (2.0 * halfZ / nz);
        expected = 0.0;
        for (int i = 0; i < nx; ++i)
          for (int j = 0; j < nz; ++j) {
            Vec3f p = panel + Vec3f((2.f * (float(i) + 0.5f) / nx - 1.f) * halfX, 0.f,
                                    (2.f * (float(j) + 0.5f) / nz - 1.f) * halfZ);
            Vec3f v = balls[k].center - p;
            double dist2 = double(lengthSq(v)), cosAxis = -double(v.y) / std::sqrt(dist2);
            expected += panelL * kPi * r2 / dist2 * cosAxis * dA;
          }
      }
      std::printf("%s: ball %d receives %.4f (expected %.4f)\n", light, k, flux[k], expected);
      EXPECT_NEAR(flux[k], expected, 0.01 * expected) << kind << ", ball " << k;
    }
  }
}

// An area light whose radiance is a checkerboard texture (9 and 1) sends each square's photons
// with that square's flux, pi L A: 9 : 1 between the squares, where the texture's mean on every
// photon would give 1 : 1 and the same total.
TEST(PhotonEmission, TexturedAreaLightEmitsEachSquaresFlux) {
  auto s = std::make_unique<Scene>();
  TriangleMesh m = makeRectangle();  // [-1, 1]^2 at z = 0 facing +z; (u, v) = ((x + 1) / 2, (y + 1) / 2)
  s->meshes.push_back(m);
  s->textures.push_back(test::checkerboard(9.f, 1.f));
  s->bsdfs.push_back(Bsdf{});
  ShapeEntry e{false, 0, 0, true, Color(5.f)};
  e.radianceTexture = 0;
  s->shapes.push_back(e);
  s->camera.width = s->camera.height = 4;
  s->finalize();
  PhotonEmitter em = makePhotonEmitter(*s);
  const SceneView& sc = s->view();
  const int n = 400000;
  double flux[2] = {0.0, 0.0};  // squares of colour 0 (u and v in the same half), of colour 1
  Sampler smp;
  for (int i = 0; i < n; ++i) {
    smp.start(uint64_t(i), 0);
    Ray r;
    Color pw;
    if (!em.emit(sc, smp, &r, &pw)) continue;
    flux[(r.o.x < 0.f) == (r.o.y < 0.f) ? 0 : 1] += pw.y / n;
  }
  // Two squares of area 1 each a colour: pi * 9 * 2 and pi * 1 * 2.
  EXPECT_NEAR(flux[0], kPi * 18.0, 0.02 * kPi * 18.0);
  EXPECT_NEAR(flux[1], kPi * 2.0, 0.02 * kPi * 2.0);
}

// Which materials a photon estimate stands in for: a rough conductor only where it is rough
// both ways (an anisotropic one sharp along either axis is followed like a mirror).
TEST(SpecularChain, AnisotropicConductorIsDiffuseLikeOnlyWhenRoughBothWays) {
  Bsdf b;
  b.type = BsdfType::RoughConductor;
  b.alpha = 0.5f;
  EXPECT_TRUE(isDiffuseLike(b, 0.3f));
  b.alphaV = 0.05f;
  EXPECT_FALSE(isDiffuseLike(b, 0.3f));
  b.alpha = 0.05f;
  b.alphaV = 0.5f;
  EXPECT_FALSE(isDiffuseLike(b, 0.3f));
  b.alpha = 0.4f;
  EXPECT_TRUE(isDiffuseLike(b, 0.3f));
  b.alpha = 0.1f;
  b.alphaV = -1.f;
  EXPECT_FALSE(isDiffuseLike(b, 0.3f));
}
