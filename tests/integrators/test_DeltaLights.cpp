// Directional and point lights against their analytic answers: a diffuse floor of albedo rho lit
// by a sun of irradiance E at angle theta reflects rho E cos(theta) / pi, and by a point light of
// intensity I at height h straight above, rho I / (pi h^2); with a constant sky of radiance 1 as
// well, rho more. Every integrator (path, direct, and the photon mappers' direct light) reaches
// delta lights only through next-event estimation.
#include <gtest/gtest.h>

#include <cmath>

#include "photon/PhotonTracing.h"
#include "render/PhotonShooter.h"
#include "scene/NameTables.h"
#include "support/TestScenes.h"

using namespace envgi;

namespace {

constexpr float kRho = 0.5f;

// The floor alone (half-size 10), seen from above through a 2-degree field, no environment.
std::unique_ptr<Scene> litFloor() {
  Bsdf floor;
  floor.reflectance = Color(kRho);
  Image grey(4, 2);
  for (float& v : grey.rgb) v = 1.f;  // replaced below: a black one would warn
  auto s = test::sphereOnFloor(floor, floor, 10.f, std::move(grey), Vec3f(0, 4, 3), Vec3f(0, 0, 0), 8, 2.f);
  s->spheres.clear();
  s->shapes.pop_back();
  s->env.reset();
  s->sampler.type = SamplerType::Sobol;
  s->sampler.sampleCount = 16;
  return s;
}

// A spot as the loader makes one (degrees in, Mitsuba's parameters).
DeltaLight spotLight(Vec3f at, Vec3f axis, float intensity, float cutoffDeg, float beamDeg) {
  DeltaLight l{at, Color(intensity), true};
  l.axis = normalize(axis);
  setSpotCone(l, cutoffDeg * kPi / 180.f, beamDeg * kPi / 180.f);
  return l;
}

DeltaLight sun(float E, float thetaDeg) {
  float t = thetaDeg * kPi / 180.f;
  return {Vec3f(std::sin(t), -std::cos(t), 0.f), Color(E), false};
}

double meanRadiance(Scene& s, const std::string& integrator) {
  s.integrator = IntegratorSettings{};
  s.integrator.type = findIntegrator(integrator);
  // A lone floor has no indirect light, so photons and gather rays add nothing to the answer:
  // few of them keep the test quick (17 s with the defaults). The grid keeps its resolution:
  // at 8 points a side its interpolation alone put the floor 1.1% too bright.
  s.integrator.photon.globalPhotons = s.integrator.photon.causticPhotons = 20000;
  s.integrator.sppm.photonCount = 10000;
  s.integrator.grid.gatherRays = 16;
  s.integrator.grid.globalPhotons = 20000;
  s.integrator.grid.causticPhotons = 5000;
  return test::renderedMean(s);
}

}  // namespace

TEST(DeltaLights, SunAndPointLightGiveTheirAnalyticRadiance) {
  for (const char* integrator : {"direct", "path", "photon", "sppm", "grid"}) {
    auto s = litFloor();
    s->deltaLights = {sun(2.f, 30.f)};
    double expected = kRho / kPi * 2.0 * std::cos(30.0 * kPi / 180.0);
    EXPECT_NEAR(meanRadiance(*s, integrator), expected, 0.01 * expected) << integrator << ", sun";
    s->deltaLights = {{Vec3f(0.f, 2.f, 0.f), Color(4.f), true}};
    expected = kRho / kPi * 4.0 / 4.0;
    EXPECT_NEAR(meanRadiance(*s, integrator), expected, 0.01 * expected) << integrator << ", point light";
    // A spot aimed 25 degrees off the floor's centre, halfway through its falloff (beam 20,
    // cutoff 30): half its intensity reaches the centre, at cos 25 from the light's height.
    DeltaLight spot = spotLight(Vec3f(0.f, 2.f, 0.f), Vec3f(std::sin(0.4363323f), -std::cos(0.4363323f), 0.f), 4.f, 30.f, 20.f);
    s->deltaLights = {spot};
    EXPECT_NEAR(meanRadiance(*s, integrator), 0.5 * expected, 0.02 * expected) << integrator << ", spot";
    // Sun and point light together: each picked half the time, their radiances add.
    s->deltaLights = {sun(2.f, 30.f), {Vec3f(0.f, 2.f, 0.f), Color(4.f), true}};
    expected = kRho / kPi * (2.0 * std::cos(30.0 * kPi / 180.0) + 1.0);
    EXPECT_NEAR(meanRadiance(*s, integrator), expected, 0.02 * expected) << integrator << ", sun and point light";
  }
}

TEST(DeltaLights, SpotFalloffIsLinearInAngleFromBeamToCutoff) {
  DeltaLight l = spotLight(Vec3f(0.f), Vec3f(0.f, 0.f, 1.f), 1.f, 30.f, 20.f);
  auto at = [&](float deg) {
    float t = deg * kPi / 180.f;
    return spotFalloff(l, Vec3f(std::sin(t), 0.f, std::cos(t)));
  };
  EXPECT_EQ(at(0.f), 1.f);
  EXPECT_EQ(at(19.9f), 1.f);
  EXPECT_NEAR(at(25.f), 0.5f, 1e-3f);
  EXPECT_NEAR(at(27.5f), 0.25f, 1e-3f);
  EXPECT_EQ(at(30.1f), 0.f);
  EXPECT_EQ(at(120.f), 0.f);
  DeltaLight point{Vec3f(0.f), Color(1.f), true};
  EXPECT_EQ(spotFalloff(point, Vec3f(0.f, 0.f, -1.f)), 1.f) << "a point light shines everywhere";
}

// A sky and a sun together: next-event estimation picks each kind half the time, and the two
// halves must still add up (the area light's and the map's MIS pdfs carry the same choice).
TEST(DeltaLights, SunUnderAConstantSkyAddsToTheSky) {
  for (const char* integrator : {"direct", "path"}) {
    auto s = litFloor();
    s->env = std::make_unique<EnvironmentMap>(EnvironmentMap::constant(Color(1.f)));
    s->deltaLights = {sun(2.f, 30.f)};
    s->sampler.sampleCount = 256;
    double expected = kRho + kRho / kPi * 2.0 * std::cos(30.0 * kPi / 180.0);
    EXPECT_NEAR(meanRadiance(*s, integrator), expected, 0.02 * expected) << integrator;
  }
}

// Each delta light is a choice of its own beside the map (and the area lights as one), as Cycles
// 3.4 shares its lamps and background: a sky, a sun and a point light get a third of the light
// samples each, and the three still add up.
TEST(DeltaLights, EachDeltaLightIsAChoiceOfItsOwn) {
  for (const char* integrator : {"direct", "path"}) {
    auto s = litFloor();
    s->env = std::make_unique<EnvironmentMap>(EnvironmentMap::constant(Color(1.f)));
    s->deltaLights = {sun(2.f, 30.f), {Vec3f(0.f, 2.f, 0.f), Color(4.f), true}};
    s->sampler.sampleCount = 256;
    s->finalize();
    const SceneView& v = s->view();
    EXPECT_FLOAT_EQ(v.envSelectProb(), 1.f / 3.f);
    EXPECT_FLOAT_EQ(v.deltaSelectProb(), 2.f / 3.f);
    EXPECT_EQ(v.areaSelectProb(), 0.f);
    double expected = kRho + kRho / kPi * (2.0 * std::cos(30.0 * kPi / 180.0) + 1.0);
    EXPECT_NEAR(meanRadiance(*s, integrator), expected, 0.02 * expected) << integrator;
  }
}

// Photons from a sun of irradiance E at angle theta onto the floor's central 2 x 2 square carry
// E cos(theta) 4; from a point light of intensity I at height h above its centre, I times the
// square's solid angle 4 atan(1 / (h sqrt(2 + h^2))).
TEST(DeltaLights, PhotonsCarryTheLightsPower) {
  auto s = litFloor();
  const float h = 2.f;
  s->deltaLights = {sun(3.f, 30.f), {Vec3f(0.f, h, 0.f), Color(4.f), true}};
  s->finalize();
  PhotonEmitter em = makePhotonEmitter(*s);
  ASSERT_TRUE(em.emitsLight(s->view()));
  const int n = 1000000;
  double arrived[2] = {0.0, 0.0};
  Sampler smp;
  for (int i = 0; i < n; ++i) {
    smp.start(uint64_t(i), 0);
    Ray r;
    Color pw;
    if (!em.emit(s->view(), smp, &r, &pw) || r.d.y >= 0.f) continue;
    float t = -r.o.y / r.d.y;
    Vec3f p = r.o + r.d * t;
    bool isPoint = r.o.y == h && r.o.x == 0.f && r.o.z == 0.f;
    if (t > 0.f && std::fabs(p.x) <= 1.f && std::fabs(p.z) <= 1.f) arrived[isPoint ? 1 : 0] += pw.y / n;
  }
  double fromSun = 3.0 * std::cos(30.0 * kPi / 180.0) * 4.0;
  double fromPoint = 4.0 * 4.0 * std::atan(1.0 / (h * std::sqrt(2.0 + h * h)));
  std::printf("arrived %.4f from the sun (expected %.4f), %.4f from the point light (expected %.4f)\n", arrived[0],
              fromSun, arrived[1], fromPoint);
  EXPECT_NEAR(arrived[0], fromSun, 0.03 * fromSun);
  EXPECT_NEAR(arrived[1], fromPoint, 0.03 * fromPoint);

  // A spot in the point light's place, aimed down, whose beam (45 degrees) holds the whole square
  // (35.3 degrees to its corners): the same power arrives, from photons drawn over its cone only.
  s->deltaLights = {spotLight(Vec3f(0.f, h, 0.f), Vec3f(0.f, -1.f, 0.f), 4.f, 60.f, 45.f)};
  s->finalize();
  em = makePhotonEmitter(*s);
  double fromSpot = 0.0;
  for (int i = 0; i < n; ++i) {
    smp.start(uint64_t(i), 0);
    Ray r;
    Color pw;
    if (!em.emit(s->view(), smp, &r, &pw) || r.d.y >= 0.f) continue;
    Vec3f p = r.o + r.d * (-r.o.y / r.d.y);
    if (std::fabs(p.x) <= 1.f && std::fabs(p.z) <= 1.f) fromSpot += pw.y / n;
  }
  std::printf("arrived %.4f from the spot (expected %.4f)\n", fromSpot, fromPoint);
  EXPECT_NEAR(fromSpot, fromPoint, 0.02 * fromPoint);
}
