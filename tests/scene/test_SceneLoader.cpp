// Every element of the supported Mitsuba subset parses into what it says; malformed files
// give "FILE:LINE: what" errors.
#include <gtest/gtest.h>

#include <fstream>

#include "cli/CliRunner.h"
#include "scene/SceneLoader.h"

using namespace envgi;

namespace {

struct Fixture {
  test::TempDir dir;
  Fixture() {
    Image img(8, 4);
    for (float& v : img.rgb) v = 0.5f;
    saveImage(img, dir.file("sky.exr"));
    std::ofstream(dir.file("tri.ply")) << "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
                                          "property float z\nelement face 1\nproperty list uchar int vertex_indices\n"
                                          "end_header\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n";
    std::ofstream(dir.file("t.obj")) << "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n";
  }
  std::string write(const std::string& name, const std::string& body) {
    std::ofstream(dir.file(name)) << body;
    return dir.file(name);
  }
  std::string scene(const std::string& inner) {
    return write("s.xml", "<scene version=\"3.0.0\">\n" + inner + "\n</scene>\n");
  }
};

const char* kSensor = R"(<sensor type="perspective">
  <float name="fov" value="60"/>
  <string name="fov_axis" value="y"/>
  <transform name="to_world"><lookat origin="0,0,5" target="0,0,0" up="0,1,0"/></transform>
  <film type="hdrfilm"><integer name="width" value="64"/><integer name="height" value="32"/>
    <rfilter type="tent"/></film>
  <sampler type="stratified"><integer name="sample_count" value="9"/><integer name="seed" value="4"/></sampler>
</sensor>)";

std::string loadError(const std::string& path, std::map<std::string, std::string> defs = {}) {
  Scene s;
  try {
    loadScene(path, defs, s);
  } catch (const std::runtime_error& e) {
    return e.what();
  }
  return "";
}

}  // namespace

TEST(SceneLoader, SensorFilmSamplerIntegrator) {
  Fixture f;
  Scene s;
  loadScene(f.scene(std::string(kSensor) + R"(
    <integrator type="direct"><integer name="emitter_samples" value="3"/><integer name="bsdf_samples" value="0"/>
      <string name="strategy" value="adaptive"/></integrator>
    <emitter type="constant"><rgb name="radiance" value="0.25"/></emitter>)"),
            {}, s);
  EXPECT_EQ(s.camera.width, 64);
  EXPECT_EQ(s.camera.height, 32);
  EXPECT_NEAR(s.camera.tanHalfY, std::tan(30.f * kPi / 180.f), 1e-5f);
  EXPECT_NEAR(s.camera.tanHalfX, 2.f * s.camera.tanHalfY, 1e-5f);
  EXPECT_EQ(s.camera.filter, FilterType::Tent);
  EXPECT_EQ(s.sampler.type, SamplerType::Stratified);
  EXPECT_EQ(s.sampler.sampleCount, 9);
  EXPECT_EQ(s.sampler.seed, 4u);
  EXPECT_EQ(s.integrator.type, IntegratorType::Direct);
  EXPECT_EQ(s.integrator.direct.emitterSamples, 3);
  EXPECT_EQ(s.integrator.direct.bsdfSamples, 0);
  EXPECT_EQ(s.integrator.env.strategy, "adaptive");
  ASSERT_TRUE(s.env);
  EXPECT_NEAR(s.env->view().eval(Vec3f(0, 1, 0)).x, 0.25f, 1e-6f);
  // The camera looks from +z towards the origin: the centre ray goes along -z.
  Ray r = s.camera.generateRay(32.f, 16.f);
  EXPECT_NEAR(r.d.z, -1.f, 1e-4f);
  // Image right is world +x for this camera (Mitsuba's convention).
  EXPECT_GT(s.camera.generateRay(60.f, 16.f).d.x, 0.f);
  EXPECT_GT(s.camera.generateRay(32.f, 2.f).d.y, 0.f);
}

TEST(SceneLoader, ShapesBsdfsEmittersTransformsDefaults) {
  Fixture f;
  f.write("inc.xml", R"(<scene version="3.0.0"><bsdf type="diffuse" id="grey"><rgb name="reflectance" value="0.2, 0.3, 0.4"/></bsdf></scene>)");
  Scene s;
  loadScene(f.scene(std::string(kSensor) + R"(
    <default name="r" value="2"/>
    <include filename="inc.xml"/>
    <emitter type="envmap"><string name="filename" value="sky.exr"/><float name="scale" value="$r"/>
      <transform name="to_world"><rotate y="1" angle="90"/></transform></emitter>
    <bsdf type="roughconductor" id="gold"><string name="material" value="Au"/><float name="alpha" value="0.2"/>
      <string name="distribution" value="ggx"/></bsdf>
    <shape type="ply"><string name="filename" value="tri.ply"/><ref id="grey"/>
      <transform name="to_world"><scale value="2"/><translate x="1"/></transform></shape>
    <shape type="sphere"><point name="center" x="0" y="1" z="0"/><float name="radius" value="$r"/><ref id="gold"/></shape>
    <shape type="rectangle"><emitter type="area"><rgb name="radiance" value="5, 4, 3"/></emitter>
      <transform name="to_world"><translate value="0, 3, 0"/></transform></shape>
    <shape type="cube"><bsdf type="twosided"><bsdf type="plastic"/></bsdf></shape>
    <shape type="disk"><boolean name="flip_normals" value="true"/><bsdf type="dielectric"><string name="int_ior" value="water"/></bsdf></shape>
    <shape type="obj"><string name="filename" value="t.obj"/><bsdf type="thindielectric"/></shape>
    <shape type="sphere"><bsdf type="roughdielectric"/></shape>
    <shape type="sphere"><bsdf type="roughplastic"/></shape>
    <shape type="sphere"><bsdf type="conductor"/></shape>)"),
            {{"r", "3"}}, s);
  ASSERT_EQ(s.shapes.size(), 9u);
  EXPECT_NEAR(s.env->view().scale, 3.f, 1e-6f) << "-D overrides <default>";
  // scale then translate, in Mitsuba's order: vertex (1,0,0) -> (2,0,0) -> (3,0,0).
  EXPECT_NEAR(s.meshes[0].positions[1].x, 3.f, 1e-5f);
  EXPECT_NEAR(s.bsdfs[size_t(s.shapes[0].bsdf)].reflectance.z, 0.4f, 1e-6f);
  EXPECT_NEAR(s.spheres[0].radius, 3.f, 1e-6f);
  const Bsdf& gold = s.bsdfs[size_t(s.shapes[1].bsdf)];
  EXPECT_EQ(gold.type, BsdfType::RoughConductor);
  EXPECT_NEAR(gold.alpha, 0.2f, 1e-6f);
  EXPECT_FALSE(gold.perfectMirror);
  EXPECT_TRUE(s.shapes[2].emissive);
  EXPECT_NEAR(s.shapes[2].radiance.x, 5.f, 1e-6f);
  EXPECT_EQ(s.lightCount(), 2u);  // two triangles
  EXPECT_TRUE(s.bsdfs[size_t(s.shapes[3].bsdf)].twoSided);
  EXPECT_EQ(s.bsdfs[size_t(s.shapes[3].bsdf)].type, BsdfType::Plastic);
  EXPECT_NEAR(s.bsdfs[size_t(s.shapes[4].bsdf)].ior, 1.333f / 1.000277f, 1e-4f);
  EXPECT_LT(s.meshes[3].normals[0].z, 0.f) << "flip_normals";
  EXPECT_EQ(s.bsdfs[size_t(s.shapes[6].bsdf)].type, BsdfType::RoughDielectric);
  EXPECT_EQ(s.bsdfs[size_t(s.shapes[8].bsdf)].type, BsdfType::Conductor);
  EXPECT_TRUE(s.bsdfs[size_t(s.shapes[8].bsdf)].perfectMirror);
}

TEST(SceneLoader, ErrorsNameFileLineAndProblem) {
  Fixture f;
  struct Case {
    std::string body, expect;
  };
  std::vector<Case> cases = {
      {"<shape type=\"teapot\"/>", "s.xml:2: unknown shape type 'teapot'"},
      {"<bsdf type=\"velvet\"/>", "unknown BSDF type 'velvet'"},
      {"<shape type=\"ply\"><string name=\"filename\" value=\"nope.ply\"/></shape>", "does not exist"},
      {"<shape type=\"sphere\"><float name=\"radius\" value=\"1.5x\"/></shape>", "'1.5x' is not a number"},
      {"<shape type=\"sphere\"><float name=\"radius\" valeu=\"1\"/></shape>", "unexpected attribute 'valeu'"},
      {"<shape type=\"sphere\"><ref id=\"nothing\"/></shape>", "unknown BSDF id 'nothing'"},
      {"<integrator type=\"bdpt\"/>", "unknown integrator 'bdpt' (path, direct, photon, sppm, grid)"},
      {"<integrator type=\"direct\"><string name=\"strategy\" value=\"magic\"/></integrator>", "unknown strategy 'magic'"},
      {"<emitter type=\"envmap\"><string name=\"filename\" value=\"missing.exr\"/></emitter>", "cannot open image"},
      {"<shape type=\"sphere\"><float name=\"radius\" value=\"$undefined\"/></shape>", "undefined parameter '$undefined'"},
      {"<shape type=\"sphere\"", "XML error"},
      {"<widget/>", "unknown element <widget>"},
      {"<emitter type=\"area\"/>", "must be inside a <shape>"},
      {"<shape type=\"rectangle\"><transform name=\"to_world\"><shear value=\"1\"/></transform></shape>", "unknown transform operation"},
      // A degenerate camera or rotation used to become NaN, and Debian's Embree aborts the
      // program on a NaN ray (found by tests/fuzz).
      {"<shape type=\"sphere\"><transform name=\"to_world\"><rotate x=\"0\" angle=\"30\"/></transform></shape>",
       "rotate: the axis must be a finite, non-zero vector"},
      {"<bsdf type=\"diffuse\" id=\"a\"/>\n<bsdf type=\"conductor\" id=\"a\"/>",
       "s.xml:3: duplicate BSDF id 'a' (first defined at " + f.dir.file("s.xml") + ":2)"},
  };
  for (const Case& c : cases) {
    std::string err = loadError(f.scene(c.body + std::string(kSensor)));
    EXPECT_NE(err.find(c.expect), std::string::npos) << "for " << c.body << "\n got: " << err;
  }
  EXPECT_NE(loadError(f.scene("")).find("no <sensor>"), std::string::npos);
  const std::pair<const char*, const char*> lookats[] = {
      {R"(origin="0,0,0" target="0,0,0" up="0,1,0")", "lookat: origin and target are the same point"},
      {R"(origin="0,0,0" target="0,0,1" up="0,0,0")", "lookat: 'up' is zero"}};
  for (const auto& [lookat, expect] : lookats) {
    std::string sensor = std::string(kSensor), original = R"(origin="0,0,5" target="0,0,0" up="0,1,0")";
    sensor.replace(sensor.find(original), original.size(), lookat);
    std::string err = loadError(f.scene(sensor));
    EXPECT_NE(err.find(expect), std::string::npos) << lookat << ": " << err;
  }
  EXPECT_NE(loadError(f.dir.file("none.xml")).find("cannot open scene file"), std::string::npos);
  f.write("bad.ply", "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nend_header\n1\n");
  EXPECT_NE(loadError(f.scene("<shape type=\"ply\"><string name=\"filename\" value=\"bad.ply\"/></shape>" +
                              std::string(kSensor)))
                .find("PLY file"),
            std::string::npos);
}

TEST(SceneLoader, HarmlessUnsupportedElementsOnlyWarn) {
  Fixture f;
  Scene s;
  EXPECT_NO_THROW(loadScene(f.scene(std::string(kSensor) + R"(
    <emitter type="point"/>
    <texture type="bitmap" id="t"/>
    <shape type="sphere"><float name="mystery" value="1"/></shape>)"),
                            {}, s));
  EXPECT_EQ(s.shapes.size(), 1u);
}
