// Next-event estimation of area lights against the exact irradiance of a polygonal Lambertian
// emitter (Lambert's formula), at points that see the light head-on and at grazing angles: the
// light sample's density alone, then with its shadow ray through Embree.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>

#include "accel/EmbreeAccel.h"
#include "cli/CliRunner.h"
#include "image/Image.h"
#include "integrators/NextEvent.h"
#include "lights/LightSampling.h"
#include "sampling/Pcg32.h"
#include "render/Renderer.h"
#include "scene/NameTables.h"
#include "scene/SceneLoader.h"
#include "support/TestScenes.h"

using namespace envgi;

namespace {

// Irradiance at p (normal n) from a one-sided polygon of radiance L (vertices counter-clockwise
// about its emitting normal), whole above p's horizon: E = L/2 sum_i angle_i (n . unit normal
// of the edge's plane).
double polygonIrradiance(const std::vector<Vec3f>& poly, Vec3f emitN, Vec3f p, Vec3f n, double L) {
  if (dot(emitN, p - poly[0]) <= 0.f) return 0.0;  // behind the emitter
  double sum = 0.0;
  for (size_t i = 0; i < poly.size(); ++i) {
    Vec3f a = normalize(poly[i] - p), b = normalize(poly[(i + 1) % poly.size()] - p);
    double angle = std::acos(std::clamp(double(dot(a, b)), -1.0, 1.0));
    Vec3f c = cross(a, b);
    sum += angle * double(dot(n, normalize(c)));
  }
  return L * 0.5 * std::fabs(sum);
}

struct LitScene {
  Scene scene;
  std::vector<Vec3f> corners;
  Vec3f normal;
};

// A 0.8 x 0.8 square light of radiance 3 (or `emitter`'s) at height 1, turned by tiltDeg about x
// from facing down; `others` adds further elements to the scene (another emitter, say).
std::unique_ptr<LitScene> squareLight(float tiltDeg,
                                      const std::string& emitter = R"(<rgb name="radiance" value="3"/>)",
                                      const std::string& others = "") {
  auto s = std::make_unique<LitScene>();
  test::TempDir dir;
  std::string path = dir.file("light.xml");
  std::ofstream(path) << R"(<scene version="3.0.0">
  <sensor type="perspective"><transform name="to_world"><lookat origin="0,3,3" target="0,0,0"/></transform>
    <film type="hdrfilm"><integer name="width" value="4"/><integer name="height" value="4"/></film></sensor>
  )" << others << R"(
  <shape type="rectangle"><transform name="to_world"><scale value="0.4"/><rotate x="1" angle=")"
                      << 90.f + tiltDeg << R"("/><translate y="1"/></transform>
    <emitter type="area">)" << emitter << R"(</emitter></shape>
  <shape type="rectangle"><transform name="to_world"><scale value="3"/><rotate x="1" angle="-90"/></transform></shape>
</scene>)";
  loadScene(path, {}, s->scene);
  float t = (90.f + tiltDeg) * kPi / 180.f;
  auto rot = [&](Vec3f v) { return Vec3f(v.x, v.y * std::cos(t) - v.z * std::sin(t), v.y * std::sin(t) + v.z * std::cos(t)); };
  for (Vec3f c : {Vec3f(-1, -1, 0), Vec3f(1, -1, 0), Vec3f(1, 1, 0), Vec3f(-1, 1, 0)})
    s->corners.push_back(rot(c * 0.4f) + Vec3f(0, 1, 0));
  s->normal = rot(Vec3f(0, 0, 1));
  return s;
}

// A point of the floor (normal +y).
SurfaceInteraction floorPoint(Vec3f p) {
  SurfaceInteraction si;
  si.p = p;
  si.ng = Vec3f(0, 1, 0);
  si.shading = Frame::fromNormal(si.ng);
  return si;
}

// The mean of L cos / pdf over next-event samples at p: the irradiance estimate.
double estimatedIrradiance(const SceneView& sc, Vec3f p, int n) {
  SurfaceInteraction si = floorPoint(p);
  Pcg32 rng;
  rng.setSeed(7, 1);
  double sum = 0.0;
  for (int i = 0; i < n; ++i) {
    LightSample ls;
    Vec2f u(rng.nextFloat(), rng.nextFloat()), u2(rng.nextFloat(), rng.nextFloat());
    if (!sampleLight(sc, si, si.ng, EnvStrategy::Importance, u, u2, &ls)) continue;
    float cosP = dot(ls.dir, si.ng);
    if (cosP > 0.f) sum += double(ls.radiance.y) * cosP / ls.pdf;
  }
  return sum / n;
}

// The same through prepareLd and its shadow ray, as the integrators take it: a white diffuse
// floor at p reflects E / pi, so pi times the mean of the light samples' values is E.
double shadowedIrradiance(const SceneView& sc, const EmbreeTracer& tracer, Vec3f p, int n) {
  SurfaceInteraction si = floorPoint(p);
  Bsdf white;
  white.reflectance = Color(1.f);
  Vec3f wo = normalize(Vec3f(0.2f, 1.f, 0.3f));
  Sampler smp;
  smp.type = SamplerType::Independent;
  smp.seed = 5;
  double sum = 0.0;
  uint64_t rays = 0;
  for (int i = 0; i < n; ++i) {
    smp.start(0, uint32_t(i));
    sum += double(sampleLd(sc, tracer, si, white, si.shading.toLocal(wo), si.ng, EnvStrategy::Importance, 1.f, 0.f, MisHeuristic::Power,
                           smp, &rays).y);
  }
  return kPi * sum / n;
}

}  // namespace

TEST(LightSampling, AreaLightIrradianceMatchesLambertsFormula) {
  for (float tilt : {0.f, 30.f, 60.f}) {
    auto s = squareLight(tilt);
    const SceneView& sc = s->scene.view();
    ASSERT_GT(sc.lightCount, 0);
    for (Vec3f p : {Vec3f(0, 0, 0), Vec3f(0.3f, 0, 0.5f), Vec3f(0, 0, -0.6f), Vec3f(0, 0, 1.5f), Vec3f(0.8f, 0, -1.f)}) {
      double exact = polygonIrradiance(s->corners, s->normal, p, Vec3f(0, 1, 0), 3.0);
      double est = estimatedIrradiance(sc, p, 200000);
      EXPECT_NEAR(est, exact, 0.01 * exact + 1e-4) << "tilt " << tilt << " at " << p.x << "," << p.y << "," << p.z;
    }
  }
}

// A light whose radiance is a checkerboard texture (9 on the squares where u and v lie in the
// same half, 1 on the others): its irradiance is the sum of each square's, Lambert's formula
// for each, at next-event estimation's samples and through prepareLd's shadow rays.
TEST(LightSampling, TexturedAreaLightIsTheSumOfItsSquares) {
  const std::string checks = R"(<texture type="checkerboard" name="radiance"><rgb name="color0" value="9"/>
    <rgb name="color1" value="1"/></texture>)";
  for (float tilt : {0.f, 30.f}) {
    auto s = squareLight(tilt, checks);
    const SceneView& sc = s->scene.view();
    ASSERT_GT(sc.lightCount, 0);
    EXPECT_EQ(sc.lights[0].radianceTexture, 0);
    // Each triangle of the rectangle holds half of each bright square and one dim one whole.
    EXPECT_NEAR(sc.lights[0].radiance.y, 5.f, 0.05f) << "the triangle's mean stands for its power";
    // The rectangle's (u, v) = ((x + 1) / 2, (y + 1) / 2) in its own frame: its quadrants, each
    // counter-clockwise about the emitting normal, with their radiance.
    const float t = (90.f + tilt) * kPi / 180.f;
    auto place = [&](float x, float y) {
      Vec3f v(x * 0.4f, y * 0.4f, 0.f);
      return Vec3f(v.x, v.y * std::cos(t) - v.z * std::sin(t), v.y * std::sin(t) + v.z * std::cos(t)) + Vec3f(0, 1, 0);
    };
    auto quad = [&](float x0, float y0) {
      return std::vector<Vec3f>{place(x0, y0), place(x0 + 1, y0), place(x0 + 1, y0 + 1), place(x0, y0 + 1)};
    };
    EmbreeAccel accel(s->scene);
    EmbreeTracer tracer{&accel};
    for (Vec3f p : {Vec3f(0, 0, 0), Vec3f(0.3f, 0, 0.5f), Vec3f(0.8f, 0, -1.f)}) {
      double exact = polygonIrradiance(quad(-1, -1), s->normal, p, Vec3f(0, 1, 0), 9.0) +
                     polygonIrradiance(quad(0, 0), s->normal, p, Vec3f(0, 1, 0), 9.0) +
                     polygonIrradiance(quad(0, -1), s->normal, p, Vec3f(0, 1, 0), 1.0) +
                     polygonIrradiance(quad(-1, 0), s->normal, p, Vec3f(0, 1, 0), 1.0);
      double uniform = polygonIrradiance(s->corners, s->normal, p, Vec3f(0, 1, 0), 5.0);
      EXPECT_NEAR(estimatedIrradiance(sc, p, 200000), exact, 0.01 * exact + 1e-4) << "tilt " << tilt << " at " << p.x << "," << p.z;
      EXPECT_NEAR(shadowedIrradiance(sc, tracer, p, 200000), exact, 0.015 * exact + 1e-4) << "tilt " << tilt;
      // Off the light's axis the squares nearer p weigh more: a uniform light of the mean is off.
      if (p.x != 0.f) {
        EXPECT_GT(std::fabs(exact - uniform), 0.03 * exact) << "tilt " << tilt << " at " << p.x;
      }
    }
  }
}

namespace {
// Draws n points on the scene's area lights and hands each to visit(light, point, radiance);
// returns how many came with a density that lightAreaPdf does not give back at the point (a
// point on a cell's edge may read its neighbour's).
template <class Visit>
int drawLightPoints(const SceneView& sc, int n, Pcg32& rng, Visit visit) {
  int mismatched = 0;
  for (int i = 0; i < n; ++i) {
    float pmf, areaPdf;
    Vec3f p, nrm;
    Color Le;
    const LightPrim& lp = sampleAreaLight(sc, Vec2f(rng.nextFloat(), rng.nextFloat()),
                                          Vec2f(rng.nextFloat(), rng.nextFloat()), &pmf, &p, &nrm, &Le, &areaPdf);
    mismatched += std::fabs(sc.lightAreaPdf(lp, p) - areaPdf) > 1e-3f * areaPdf;
    visit(lp, p, Le);
  }
  return mismatched;
}
}  // namespace

namespace {
// An 8 x 8 bitmap light, nearest-filtered so that it is constant over each texel: one texel
// (5, 2) at 100, the rest at 0.1. Texel (i, j) covers u in [i/8, (i+1)/8], v in [j/8, (j+1)/8]
// (row 0 of the image at v = 0).
constexpr int kTexels = 8, kBrightX = 5, kBrightY = 2;
float texelRadiance(int i, int j) { return i == kBrightX && j == kBrightY ? 100.f : 0.1f; }

std::unique_ptr<LitScene> bitmapLight(test::TempDir& dir) {
  Image img(kTexels, kTexels);
  for (int j = 0; j < kTexels; ++j)
    for (int i = 0; i < kTexels; ++i) img.set(i, j, Color(texelRadiance(i, j)));
  saveImage(img, dir.file("spot.pfm"));
  return squareLight(0.f, R"(<texture type="bitmap" name="radiance"><string name="filename" value=")" +
                              dir.file("spot.pfm") + R"("/><string name="filter_type" value="nearest"/></texture>)");
}

// The light's texel (i, j) as a quad in the world: the rectangle's (u, v) = ((x + 1) / 2,
// (y + 1) / 2) in its frame, scaled by 0.4, facing down at height 1.
std::vector<Vec3f> texelQuad(int i, int j) {
  auto place = [](float u, float v) { return Vec3f(0.4f * (2.f * u - 1.f), 1.f, 0.4f * (2.f * v - 1.f)); };
  const float s = 1.f / kTexels;
  return {place(i * s, j * s), place((i + 1) * s, j * s), place((i + 1) * s, (j + 1) * s), place(i * s, (j + 1) * s)};
}

// Mean and variance of next-event estimation's L cos / pdf at floor point p.
std::pair<double, double> irradianceSamples(const SceneView& sc, Vec3f p, int n) {
  SurfaceInteraction si = floorPoint(p);
  Pcg32 rng(9, 4);
  double sum = 0.0, sumSq = 0.0;
  for (int i = 0; i < n; ++i) {
    LightSample ls;
    Vec2f u(rng.nextFloat(), rng.nextFloat()), u2(rng.nextFloat(), rng.nextFloat());
    double f = 0.0;
    if (sampleLight(sc, si, si.ng, EnvStrategy::Importance, u, u2, &ls)) {
      float cosP = dot(ls.dir, si.ng);
      if (cosP > 0.f) f = double(ls.radiance.y) * cosP / ls.pdf;
    }
    sum += f;
    sumSq += f * f;
  }
  const double mean = sum / n;
  return {mean, sumSq / n - mean * mean};
}
}  // namespace

// A textured light's points are drawn by its texture: most land on the one bright texel (1/64
// of the area), the density handed back with each point is the one lightAreaPdf finds there,
// and that density integrates to 1 over each triangle.
TEST(LightSampling, TexturedLightDrawsPointsByItsTexture) {
  test::TempDir dir;
  auto s = bitmapLight(dir);
  const SceneView& sc = s->scene.view();
  ASSERT_EQ(sc.lightCount, 2);
  for (int l = 0; l < 2; ++l) EXPECT_GT(sc.lights[l].cells, 1) << "triangle " << l << " is cut into cells";
  Pcg32 rng(21, 5);
  const int n = 100000;
  int bright = 0;
  const int mismatched = drawLightPoints(sc, n, rng, [&](const LightPrim& lp, Vec3f p, Color Le) {
    const MeshView& m = sc.meshes[lp.geomId];
    const uint32_t* ix = m.indices + 3 * lp.primId;
    const Vec2f b = triangleBarycentrics(p, m.positions[ix[0]], m.positions[ix[1]], m.positions[ix[2]]);
    const Vec2f uv = meshUv(m, ix[0], ix[1], ix[2], b.x, b.y);
    bright += int(uv.x * kTexels) == kBrightX && int(uv.y * kTexels) == kBrightY;
    EXPECT_NEAR(Le.y, texelRadiance(std::min(int(uv.x * kTexels), kTexels - 1), std::min(int(uv.y * kTexels), kTexels - 1)),
                1e-3f + 0.01f * Le.y)
        << "the radiance handed back is the texture's at the point";
  });
  EXPECT_LE(mismatched, n / 1000) << "sampled densities that lightAreaPdf does not give back";
  // The bright texel holds 100 / (100 + 63 x 0.1) = 94% of the power, uniform points put 1.6%
  // there; half-texel cells across its edges take some of its share (71% measured).
  EXPECT_GT(double(bright) / n, 0.6) << bright << " of " << n;
  for (int l = 0; l < 2; ++l) {
    const LightPrim& lp = sc.lights[l];
    const MeshView& m = sc.meshes[lp.geomId];
    const uint32_t* ix = m.indices + 3 * lp.primId;
    double integral = 0.0;
    const int k = 200000;
    for (int i = 0; i < k; ++i) {
      const Vec2f b = sampleUniformTriangle(Vec2f(rng.nextFloat(), rng.nextFloat()));
      const Vec3f q = m.positions[ix[0]] * (1.f - b.x - b.y) + m.positions[ix[1]] * b.x + m.positions[ix[2]] * b.y;
      integral += double(sc.lightAreaPdf(lp, q)) * double(lp.area) / k;
    }
    EXPECT_NEAR(integral, 1.0, 0.03) << "triangle " << l;
  }
}

// Next-event estimation under that light gives the sum of Lambert's formula over its 64
// texels, drawn by the texture or uniformly (the cells switched off), and by the texture its
// samples vary less than a tenth as much.
TEST(LightSampling, TexturedLightNextEventMatchesItsTexelsWithLessVariance) {
  test::TempDir dir;
  auto s = bitmapLight(dir);
  const SceneView& sc = s->scene.view();
  std::vector<LightPrim> uniformLights(sc.lights, sc.lights + sc.lightCount);
  for (LightPrim& lp : uniformLights) lp.cells = 0;
  SceneView uniform = sc;
  uniform.lights = uniformLights.data();
  const int n = 200000;
  for (Vec3f p : {Vec3f(0, 0, 0), Vec3f(0.3f, 0, 0.5f), Vec3f(0.8f, 0, -1.f)}) {
    double exact = 0.0;
    for (int j = 0; j < kTexels; ++j)
      for (int i = 0; i < kTexels; ++i)
        exact += polygonIrradiance(texelQuad(i, j), s->normal, p, Vec3f(0, 1, 0), texelRadiance(i, j));
    auto [meanCells, varCells] = irradianceSamples(sc, p, n);
    auto [meanUniform, varUniform] = irradianceSamples(uniform, p, n);
    EXPECT_NEAR(meanCells, exact, 4.0 * std::sqrt(varCells / n) + 0.002 * exact) << "at " << p.x << "," << p.z;
    EXPECT_NEAR(meanUniform, exact, 4.0 * std::sqrt(varUniform / n) + 0.002 * exact) << "at " << p.x << "," << p.z;
    EXPECT_LT(varCells, 0.1 * varUniform) << "at " << p.x << "," << p.z;
    std::printf("at (%.1f, %.1f): exact %.5f, by texture %.5f (variance %.4g), uniform %.5f (variance %.4g)\n", p.x, p.z,
                exact, meanCells, varCells, meanUniform, varUniform);
  }
}

namespace {
// A sphere light of radius 0.5 at height 1.5 with an 8 x 4 nearest-filtered texture over its
// (u, v): one texel (5, 1) at 100, the rest at 0.1 (its pole along z, so the bright texel faces
// sideways and down).
float sphereTexel(int i, int j) { return i == 5 && j == 1 ? 100.f : 0.1f; }
std::unique_ptr<Scene> texturedSphereLight() {
  auto s = std::make_unique<Scene>();
  s->spheres.push_back({Vec3f(0.f, 1.5f, 0.f), 0.5f, false});
  Texture t;
  t.params.type = TextureType::Bitmap;
  t.params.width = 8;
  t.params.height = 4;
  t.params.bilinear = false;
  for (int j = 0; j < 4; ++j)
    for (int i = 0; i < 8; ++i) t.texels.push_back(Color(sphereTexel(i, j)));
  s->textures.push_back(t);
  ShapeEntry e{true, 0, 0, true, Color((100.f + 31.f * 0.1f) / 32.f)};
  e.radianceTexture = 0;
  s->shapes.push_back(e);
  s->finalize();
  return s;
}

// The irradiance at floor point p from that sphere, by the midpoint rule over (azimuth, z),
// which are uniform by area on a sphere.
double sphereIrradiance(Vec3f p) {
  const Vec3f c(0.f, 1.5f, 0.f);
  const double r = 0.5;
  const int nPhi = 2000, nZ = 1000;
  double sum = 0.0;
  for (int a = 0; a < nPhi; ++a)
    for (int b = 0; b < nZ; ++b) {
      const double phi = 2.0 * kPi * (a + 0.5) / nPhi, z = 1.0 - 2.0 * (b + 0.5) / nZ, rho = std::sqrt(1.0 - z * z);
      const double nx = rho * std::cos(phi), ny = rho * std::sin(phi), nz = z;
      const double x = c.x + r * nx - p.x, y = c.y + r * ny - p.y, w = c.z + r * nz - p.z;
      const double d2 = x * x + y * y + w * w, d = std::sqrt(d2);
      const double cosP = y / d, cosL = -(nx * x + ny * y + nz * w) / d;
      if (cosP <= 0.0 || cosL <= 0.0) continue;
      const int i = std::min(7, int(phi / (2.0 * kPi) * 8)), j = std::min(3, int(std::acos(z) / kPi * 4));
      sum += sphereTexel(i, j) * cosP * cosL / d2;
    }
  return sum * r * r * (2.0 * kPi / nPhi) * (2.0 / nZ);
}
}  // namespace

// The same for a sphere light: its points follow its texture over its (u, v) cells, the
// density handed back is lightAreaPdf's and integrates to 1, and next-event estimation meets
// the irradiance integrated numerically, with far less variance than uniform points.
TEST(LightSampling, TexturedSphereLightDrawsPointsByItsTexture) {
  auto s = texturedSphereLight();
  const SceneView& sc = s->view();
  ASSERT_EQ(sc.lightCount, 1);
  const LightPrim& lp = sc.lights[0];
  EXPECT_GT(lp.cells, 1) << "the sphere is cut into cells";
  Pcg32 rng(23, 8);
  const int n = 100000;
  int bright = 0;
  const int mismatched = drawLightPoints(sc, n, rng, [&](const LightPrim&, Vec3f, Color Le) { bright += Le.y > 50.f; });
  EXPECT_LE(mismatched, n / 1000) << "sampled densities that lightAreaPdf does not give back";
  // The bright texel, 4.4% of the area (an eighth of the band from 45 to 90 degrees), holds
  // 4.42 / (4.42 + 0.1 x 0.956) = 98% of the power; uniform points put 4.4% there.
  EXPECT_GT(double(bright) / n, 0.85) << bright << " of " << n;
  double integral = 0.0;
  const int k = 200000;
  for (int i = 0; i < k; ++i) {
    const Vec3f q = Vec3f(0.f, 1.5f, 0.f) + sampleUniformSphere(Vec2f(rng.nextFloat(), rng.nextFloat())) * 0.5f;
    integral += double(sc.lightAreaPdf(lp, q)) * double(lp.area) / k;
  }
  EXPECT_NEAR(integral, 1.0, 0.03);
  std::vector<LightPrim> uniformLights(sc.lights, sc.lights + sc.lightCount);
  uniformLights[0].cells = 0;
  SceneView uniform = sc;
  uniform.lights = uniformLights.data();
  for (Vec3f p : {Vec3f(0, 0, 0), Vec3f(0.6f, 0, 0.3f), Vec3f(-0.5f, 0, -0.8f)}) {
    const double exact = sphereIrradiance(p);
    auto [meanCells, varCells] = irradianceSamples(sc, p, 200000);
    auto [meanUniform, varUniform] = irradianceSamples(uniform, p, 200000);
    EXPECT_NEAR(meanCells, exact, 4.0 * std::sqrt(varCells / 200000) + 0.003 * exact) << "at " << p.x << "," << p.z;
    EXPECT_NEAR(meanUniform, exact, 4.0 * std::sqrt(varUniform / 200000) + 0.003 * exact) << "at " << p.x << "," << p.z;
    EXPECT_LT(varCells, 0.2 * varUniform) << "at " << p.x << "," << p.z;
    std::printf("sphere, at (%.1f, %.1f): exact %.5f, by texture %.5f (variance %.4g), uniform %.5f (variance %.4g)\n",
                p.x, p.z, exact, meanCells, varCells, meanUniform, varUniform);
  }
}

// A camera sees a textured light's texture, in every integrator that shows emitters: a
// checkerboard (9 and 1) rectangle filling an orthographic view reads 9 and 1 in its quadrants.
TEST(LightSampling, ATexturedLightSeenDirectlyShowsItsTexture) {
  for (IntegratorType type : {IntegratorType::Path, IntegratorType::Direct, IntegratorType::Photon,
                              IntegratorType::Sppm, IntegratorType::Grid}) {
    Scene s;
    s.meshes.push_back(makeRectangle());
    s.textures.push_back(test::checkerboard(9.f, 1.f));
    Bsdf black;
    black.reflectance = Color(0.f);
    s.bsdfs.push_back(black);
    ShapeEntry e{false, 0, 0, true, Color(5.f)};
    e.radianceTexture = 0;
    s.shapes.push_back(e);
    s.camera.toWorld = lookAt(Vec3f(0, 0, 5), Vec3f(0, 0, 0), Vec3f(0, 1, 0));
    s.camera.width = s.camera.height = 8;
    s.camera.orthographic = true;
    s.camera.tanHalfX = s.camera.tanHalfY = 1.f;
    s.camera.filter = makeFilter(FilterType::Box);
    s.sampler.sampleCount = 4;
    s.integrator.type = type;
    Image img = test::renderedImage(s);
    // Looking down -z, image right is world +x: the top-left pixel sees x < 0, y > 0 (colour 1),
    // the top-right x > 0, y > 0 (colour 0).
    EXPECT_NEAR(img.at(1, 1).y, 1.f, 1e-4f) << integratorName(type);
    EXPECT_NEAR(img.at(6, 1).y, 9.f, 1e-4f) << integratorName(type);
    EXPECT_NEAR(img.at(6, 6).y, 1.f, 1e-4f) << integratorName(type);
    EXPECT_NEAR(img.at(1, 6).y, 9.f, 1e-4f) << integratorName(type);
  }
}

// One draw picks the kind of light and then serves that light, stretched back over [0, 1): with a
// map and a square light each taking half, evenly spaced u.x must reach the whole map and the
// whole light. Read raw, the map's half would see only u.x < 1/2 (half of its azimuths) and the
// light's only u.x >= 1/2 (half of its width).
TEST(LightSampling, TheKindsDrawServesTheChosenLightWhole) {
  auto s = squareLight(0.f, R"(<rgb name="radiance" value="3"/>)",
                       R"(<emitter type="constant"><rgb name="radiance" value="1"/></emitter>)");
  const SceneView& sc = s->scene.view();
  ASSERT_FLOAT_EQ(sc.envSelectProb(), 0.5f);
  ASSERT_FLOAT_EQ(sc.areaSelectProb(), 0.5f);
  SurfaceInteraction si = floorPoint(Vec3f(0, 0, 0));
  const int n = 256;
  std::vector<float> azimuths;
  float xMin = 1.f, xMax = -1.f;
  for (int i = 0; i < n; ++i) {
    LightSample ls;
    if (!sampleLight(sc, si, Vec3f(0.f), EnvStrategy::Importance, Vec2f((i + 0.5f) / n, 0.3f), Vec2f(0.5f, 0.5f), &ls))
      continue;
    if (ls.environment) {
      azimuths.push_back(std::atan2(ls.dir.z, ls.dir.x));
    } else {
      float x = si.p.x + ls.dir.x * ls.dist;
      xMin = std::min(xMin, x), xMax = std::max(xMax, x);
    }
  }
  ASSERT_EQ(azimuths.size(), size_t(n / 2));
  std::sort(azimuths.begin(), azimuths.end());
  float gap = azimuths.front() + 2.f * kPi - azimuths.back();  // around the circle
  for (size_t k = 1; k < azimuths.size(); ++k) gap = std::max(gap, azimuths[k] - azimuths[k - 1]);
  EXPECT_LT(gap, 4.f * 2.f * kPi / float(n / 2)) << "the map's draws leave a gap of " << gap << " rad";
  // The light's own draws over the whole of [0, 1) reach from wantMin to wantMax.
  float wantMin = 1.f, wantMax = -1.f;
  for (int i = 0; i < n; ++i) {
    float pmf, areaPdf;
    Vec3f p, nl;
    Color Le;
    sampleAreaLight(sc, Vec2f(0.5f, 0.5f), Vec2f((i + 0.5f) / n, 0.3f), &pmf, &p, &nl, &Le, &areaPdf);
    wantMin = std::min(wantMin, p.x), wantMax = std::max(wantMax, p.x);
  }
  ASSERT_GT(wantMax - wantMin, 0.2f);
  EXPECT_NEAR(xMin, wantMin, 0.02f * (wantMax - wantMin));
  EXPECT_NEAR(xMax, wantMax, 0.02f * (wantMax - wantMin));
}

// Seen edge-on, a tilted light used to shadow itself: the shadow ray, kept parallel to the light
// sample's direction from the offset origin, met the light's plane before its end. The floor at
// z = 1.5 under the light turned 30 degrees got 8.8e-6 of its 0.0226.
TEST(LightSampling, ShadowRaysReachAGrazingLight) {
  for (float tilt : {0.f, 30.f, 60.f}) {
    auto s = squareLight(tilt);
    EmbreeAccel accel(s->scene);
    for (Vec3f p : {Vec3f(0, 0, 0), Vec3f(0.3f, 0, 0.5f), Vec3f(0, 0, 1.5f), Vec3f(0.8f, 0, -1.f), Vec3f(0, 0, 1.2f)}) {
      double exact = polygonIrradiance(s->corners, s->normal, p, Vec3f(0, 1, 0), 3.0);
      EXPECT_NEAR(shadowedIrradiance(s->scene.view(), EmbreeTracer{&accel}, p, 100000), exact, 0.015 * exact + 1e-4)
          << "tilt " << tilt << " at " << p.x << "," << p.y << "," << p.z;
    }
  }
}
