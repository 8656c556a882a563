// Every element of the supported Mitsuba subset parses into what it says; malformed files
// give "FILE:LINE: what" errors.
#include <gtest/gtest.h>

#include <cmath>
#include <fstream>

#include "cli/CliRunner.h"
#include "envmap/LightProbe.h"
#include "materials/BsdfFactory.h"
#include "scene/SceneLoader.h"
#include "support/SerializedFile.h"

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

// kSensor's scene with `xml` in place of its film's tent filter, or before it where keepFilter.
std::string sensorWithFilm(Fixture& f, const std::string& xml, bool keepFilter) {
  const std::string tent = "<rfilter type=\"tent\"/>";
  std::string body = kSensor;
  body.replace(body.find(tent), keepFilter ? 0 : tent.size(), xml);
  return f.scene(body);
}

// Each scene body (after kSensor) must fail to load with its message, naming the file and line.
template <size_t N>
void expectErrors(Fixture& f, const std::pair<const char*, const char*> (&bad)[N]) {
  for (const auto& [xml, message] : bad) {
    Scene s;
    try {
      loadScene(f.scene(std::string(kSensor) + xml), {}, s);
      ADD_FAILURE() << "accepted: " << xml;
    } catch (const std::runtime_error& e) {
      EXPECT_NE(std::string(e.what()).find(message), std::string::npos) << e.what();
      EXPECT_NE(std::string(e.what()).find(".xml:"), std::string::npos) << "names the file and line: " << e.what();
    }
  }
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
  EXPECT_EQ(s.camera.filter.type, FilterType::Tent);
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
  EXPECT_FALSE(s.camera.hasLens());

  // thinlens: Mitsuba's aperture_radius (required) and focus_distance (far_clip unless given).
  const std::string persp = "type=\"perspective\">";
  std::string lens = kSensor;
  lens.replace(lens.find(persp), persp.size(), "type=\"thinlens\"><float name=\"aperture_radius\" value=\"0.1\"/>");
  Scene t;
  loadScene(f.scene(lens), {}, t);
  EXPECT_NEAR(t.camera.apertureRadius, 0.1f, 1e-7f);
  EXPECT_NEAR(t.camera.focusDistance, t.camera.farClip, 1e-3f);
  std::string focused = lens;
  focused.replace(focused.find("<float name=\"aperture_radius\""), 0, "<float name=\"focus_distance\" value=\"3.5\"/>");
  Scene u;
  loadScene(f.scene(focused), {}, u);
  EXPECT_NEAR(u.camera.focusDistance, 3.5f, 1e-6f);
  std::string noRadius = kSensor;
  noRadius.replace(noRadius.find(persp), persp.size(), "type=\"thinlens\">");
  EXPECT_NE(loadError(f.scene(noRadius)).find("thinlens needs an 'aperture_radius'"), std::string::npos);
  std::string negative = lens;
  negative.replace(negative.find("value=\"0.1\""), 11, "value=\"-0.1\"");
  EXPECT_NE(loadError(f.scene(negative)).find("aperture_radius must be >= 0"), std::string::npos);
  std::string unfocused = focused;
  unfocused.replace(unfocused.find("value=\"3.5\""), 11, "value=\"0\"");
  EXPECT_NE(loadError(f.scene(unfocused)).find("focus_distance must be positive"), std::string::npos);
}

// Mitsuba's orthographic sensor: the near plane's [-1, 1] x [-1/aspect, 1/aspect], sized by
// to_world's scale, and no field of view (a fov is warned about and ignored, as the camera has
// none); a thin lens's aperture is an error there, as in Mitsuba.
TEST(SceneLoader, OrthographicSensor) {
  Fixture f;
  const std::string ortho = R"(<sensor type="orthographic">
  <float name="fov" value="60"/>
  <transform name="to_world"><scale x="4" y="4"/><lookat origin="0,0,5" target="0,0,0" up="0,1,0"/></transform>
  <film type="hdrfilm"><integer name="width" value="64"/><integer name="height" value="32"/></film>
</sensor>)";
  Scene s;
  loadScene(f.scene(ortho), {}, s);
  EXPECT_TRUE(s.camera.orthographic);
  EXPECT_FLOAT_EQ(s.camera.tanHalfX, 1.f);
  EXPECT_FLOAT_EQ(s.camera.tanHalfY, 0.5f);
  // Image left is world -x for this camera (+x of its frame), 4 units from the axis; the top
  // is 2 units up; every ray runs along -z.
  Ray left = s.camera.generateRay(0.f, 16.f), top = s.camera.generateRay(32.f, 0.f);
  EXPECT_NEAR(left.o.x, -4.f, 1e-4f);
  EXPECT_NEAR(top.o.y, 2.f, 1e-4f);
  EXPECT_NEAR(left.o.z, 5.f - 0.01f, 1e-4f);
  EXPECT_NEAR(left.d.z, -1.f, 1e-6f);
  EXPECT_NEAR(top.d.z, -1.f, 1e-6f);
  EXPECT_FALSE(s.camera.hasLens());
  std::string lens = ortho;
  lens.replace(lens.find("<float name=\"fov\""), 0, "<float name=\"aperture_radius\" value=\"0.1\"/>");
  std::string e = loadError(f.scene(lens));
  EXPECT_NE(e.find("sensor 'orthographic' has no property 'aperture_radius'"), std::string::npos) << e;
  // The same scene with a perspective sensor is not orthographic.
  Scene p;
  loadScene(f.scene(kSensor), {}, p);
  EXPECT_FALSE(p.camera.orthographic);
}

// Mitsuba's crop window on the film: the image is the window, the view's aspect the whole
// film's; a window that leaves the film is an error with the line.
TEST(SceneLoader, FilmCropWindow) {
  Fixture f;
  auto withCrop = [&](const std::string& crop) { return sensorWithFilm(f, crop, true); };
  Scene s;
  loadScene(withCrop(R"(<integer name="crop_offset_x" value="10"/><integer name="crop_offset_y" value="4"/>
    <integer name="crop_width" value="20"/><integer name="crop_height" value="8"/>)"),
            {}, s);
  EXPECT_EQ(s.camera.width, 20);
  EXPECT_EQ(s.camera.height, 8);
  EXPECT_EQ(s.camera.filmWidth, 64);
  EXPECT_EQ(s.camera.filmHeight, 32);
  EXPECT_EQ(s.camera.cropX, 10);
  EXPECT_EQ(s.camera.cropY, 4);
  EXPECT_NEAR(s.camera.tanHalfX, 2.f * s.camera.tanHalfY, 1e-5f) << "the aspect of the 64 x 32 film";
  // A window of the whole film is no crop at all.
  Scene w;
  loadScene(withCrop(R"(<integer name="crop_width" value="64"/>)"), {}, w);
  EXPECT_EQ(w.camera.filmWidth, 0);
  EXPECT_EQ(w.camera.width, 64);
  for (const char* bad : {R"(<integer name="crop_offset_x" value="50"/><integer name="crop_width" value="20"/>)",
                          R"(<integer name="crop_height" value="0"/>)", R"(<integer name="crop_offset_y" value="-1"/>)"}) {
    std::string e = loadError(withCrop(bad));
    EXPECT_NE(e.find("does not lie within the 64 x 32 film"), std::string::npos) << e;
    EXPECT_NE(e.find(".xml:"), std::string::npos) << e;
  }
}

// Each of Mitsuba's rfilters with the parameters its plugin takes, Mitsuba's defaults where none
// is given; a value out of range, or a parameter of another filter, is an error with the line.
TEST(SceneLoader, EveryMitsubaFilterWithItsParameters) {
  Fixture f;
  auto withFilter = [&](const std::string& rfilter) { return sensorWithFilm(f, rfilter, false); };
  auto filterOf = [&](const std::string& rfilter) {
    Scene s;
    loadScene(withFilter(rfilter), {}, s);
    return s.camera.filter;
  };
  EXPECT_EQ(filterOf("<rfilter type=\"box\"/>").radius, 0.5f);
  EXPECT_EQ(filterOf("<rfilter type=\"tent\"/>").radius, 1.f);
  EXPECT_EQ(filterOf("<rfilter type=\"tent\"><float name=\"radius\" value=\"1.5\"/></rfilter>").radius, 1.5f);
  ReconstructionFilter g = filterOf("<rfilter type=\"gaussian\"><float name=\"stddev\" value=\"0.25\"/></rfilter>");
  EXPECT_EQ(g.stddev, 0.25f);
  EXPECT_EQ(g.radius, 1.f);
  ReconstructionFilter m = filterOf("<rfilter type=\"mitchell\"><float name=\"B\" value=\"0.5\"/>"
                                    "<float name=\"C\" value=\"0.25\"/></rfilter>");
  EXPECT_EQ(m.type, FilterType::Mitchell);
  EXPECT_EQ(m.b, 0.5f);
  EXPECT_EQ(m.c, 0.25f);
  EXPECT_NEAR(filterOf("<rfilter type=\"mitchell\"/>").b, 1.f / 3.f, 1e-7f);
  ReconstructionFilter cr = filterOf("<rfilter type=\"catmullrom\"/>");
  EXPECT_EQ(cr.type, FilterType::CatmullRom);
  EXPECT_EQ(cr.c, 0.5f);
  EXPECT_EQ(filterOf("<rfilter type=\"lanczos\"/>").radius, 3.f);
  EXPECT_EQ(filterOf("<rfilter type=\"lanczos\"><integer name=\"lobes\" value=\"2\"/></rfilter>").radius, 2.f);
  // Errors: the line of the rfilter (line 7 of the file), and what is wrong.
  std::string e = loadError(withFilter("<rfilter type=\"tent\"><float name=\"radius\" value=\"0\"/></rfilter>"));
  EXPECT_NE(e.find("s.xml:7: rfilter 'tent': tent's radius must be positive, got 0"), std::string::npos) << e;
  e = loadError(withFilter("<rfilter type=\"lanczos\"><integer name=\"lobes\" value=\"0\"/></rfilter>"));
  EXPECT_NE(e.find("lanczos's lobes must be 1 to 64"), std::string::npos) << e;
  e = loadError(withFilter("<rfilter type=\"gaussian\"><float name=\"stddev\" value=\"-1\"/></rfilter>"));
  EXPECT_NE(e.find("gaussian's stddev must be positive"), std::string::npos) << e;
  e = loadError(withFilter("<rfilter type=\"catmullrom\"><float name=\"radius\" value=\"2\"/></rfilter>"));
  EXPECT_NE(e.find("has no property 'radius'"), std::string::npos) << e;
  e = loadError(withFilter("<rfilter type=\"mitchel\"/>"));
  EXPECT_NE(e.find("unknown rfilter type 'mitchel'"), std::string::npos) << e;
}

// Every index of refraction Mitsuba 3 names, by name, with Mitsuba's value (a few checked
// against Mitsuba 3.9.1's dielectric: water ice 1.31, glycerol 1.4729, pet 1.575); an unknown
// name is an error.
TEST(SceneLoader, EveryMitsubaIndexOfRefractionName) {
  Fixture f;
  const std::pair<const char*, float> names[] = {
      {"helium", 1.000036f}, {"hydrogen", 1.000132f}, {"carbon dioxide", 1.00045f}, {"acetone", 1.36f},
      {"ethanol", 1.361f}, {"carbon tetrachloride", 1.461f}, {"glycerol", 1.4729f}, {"benzene", 1.501f},
      {"silicone oil", 1.52045f}, {"bromine", 1.661f}, {"water ice", 1.31f}, {"pyrex", 1.47f},
      {"sodium chloride", 1.544f}, {"amber", 1.55f}, {"pet", 1.575f}, {"water", 1.333f}, {"diamond", 2.419f}};
  for (const auto& [name, ior] : names) {
    Scene s;
    loadScene(f.scene(std::string(kSensor) + R"(<shape type="sphere"><bsdf type="dielectric"><string name="int_ior" value=")" +
                      name + R"("/><string name="ext_ior" value="vacuum"/></bsdf></shape>)"),
              {}, s);
    EXPECT_NEAR(s.bsdfs[size_t(s.shapes[0].bsdf)].ior, ior, 1e-6f) << name;
  }
  std::pair<const char*, const char*> bad[] = {
      {R"(<shape type="sphere"><bsdf type="dielectric"><string name="int_ior" value="mead"/></bsdf></shape>)",
       "unknown index of refraction 'mead'"}};
  expectErrors(f, bad);
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
    <shape type="sphere"><bsdf type="conductor"/></shape>
    <shape type="sphere"/>)"),
            {{"r", "3"}}, s);
  ASSERT_EQ(s.shapes.size(), 10u);
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
  // Mitsuba's default BSDF: diffuse 0.5, black on an area light.
  EXPECT_EQ(s.bsdfs[size_t(s.shapes[2].bsdf)].type, BsdfType::Diffuse);
  EXPECT_EQ(s.bsdfs[size_t(s.shapes[2].bsdf)].reflectance.y, 0.f);
  EXPECT_EQ(s.bsdfs[size_t(s.shapes[9].bsdf)].type, BsdfType::Diffuse);
  EXPECT_EQ(s.bsdfs[size_t(s.shapes[9].bsdf)].reflectance.y, 0.5f);
  EXPECT_TRUE(s.bsdfs[size_t(s.shapes[3].bsdf)].twoSided);
  EXPECT_EQ(s.bsdfs[size_t(s.shapes[3].bsdf)].type, BsdfType::Plastic);
  EXPECT_NEAR(s.bsdfs[size_t(s.shapes[4].bsdf)].ior, 1.333f / 1.000277f, 1e-4f);
  EXPECT_LT(s.meshes[3].normals[0].z, 0.f) << "flip_normals";
  EXPECT_EQ(s.bsdfs[size_t(s.shapes[6].bsdf)].type, BsdfType::RoughDielectric);
  // Mitsuba's rough BSDFs are Beckmann unless the scene says ggx; isotropic unless given
  // alpha_u and alpha_v.
  EXPECT_FALSE(bsdfIsAnisotropic(gold));
  EXPECT_EQ(gold.distribution, MicrofacetType::GGX);
  EXPECT_EQ(s.bsdfs[size_t(s.shapes[6].bsdf)].distribution, MicrofacetType::Beckmann);
  EXPECT_EQ(s.bsdfs[size_t(s.shapes[7].bsdf)].distribution, MicrofacetType::Beckmann);
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
      {"<bsdf type=\"velvet\"/>", "unknown BSDF type 'velvet' (diffuse, conductor, roughconductor,"},
      {"<bsdf type=\"roughconductor\"><string name=\"distribution\" value=\"phong\"/></bsdf>",
       "roughconductor distribution must be beckmann or ggx, not 'phong'"},
      {"<bsdf type=\"roughconductor\"><float name=\"alpha\" value=\"0.2\"/><float name=\"alpha_u\" value=\"0.1\"/></bsdf>",
       "give either alpha or alpha_u and alpha_v, not both"},
      {"<bsdf type=\"roughdielectric\"><float name=\"alpha_u\" value=\"0.1\"/><float name=\"alpha_v\" value=\"-1\"/></bsdf>",
       "alpha_v must be in (0, 4]"},
      {"<bsdf type=\"roughplastic\"><float name=\"int_ior\" value=\"1.3\"/><float name=\"ext_ior\" value=\"1.3\"/></bsdf>",
       "int_ior and ext_ior must differ (both are 1.3)"},
      {"<bsdf type=\"dielectric\"><string name=\"int_ior\" value=\"air\"/></bsdf>", "int_ior and ext_ior must differ"},
      {"<shape type=\"ply\"><string name=\"filename\" value=\"nope.ply\"/></shape>", "does not exist"},
      {"<shape type=\"sphere\"><float name=\"radius\" value=\"1.5x\"/></shape>", "'1.5x' is not a number"},
      {"<shape type=\"sphere\"><float name=\"radius\" valeu=\"1\"/></shape>", "unexpected attribute 'valeu'"},
      {"<shape type=\"sphere\"><ref id=\"nothing\"/></shape>", "unknown BSDF id 'nothing'"},
      {"<integrator type=\"bdpt\"/>", "unknown integrator 'bdpt' (path, direct, photon, sppm, grid)"},
      {"<integrator type=\"direct\"><string name=\"strategy\" value=\"magic\"/></integrator>", "unknown strategy 'magic'"},
      {"<emitter type=\"envmap\"><string name=\"filename\" value=\"missing.exr\"/></emitter>", "cannot open image"},
      {"<emitter type=\"envmap\"><string name=\"filename\" value=\"sky.exr\"/><string name=\"layout\" value=\"cube\"/></emitter>",
       "layout must be latlong, angular, mirrorball or cross, not 'cube'"},
      {"<emitter type=\"envmap\"><string name=\"filename\" value=\"sky.exr\"/><string name=\"layout\" value=\"angular\"/></emitter>",
       "a light probe is a square image of at least 2x2, not 8x4"},
      {"<shape type=\"sphere\"><float name=\"radius\" value=\"$undefined\"/></shape>", "undefined parameter '$undefined'"},
      {"<shape type=\"sphere\"", "XML error"},
      {"<widget/>", "unknown element <widget>"},
      {"<emiter type=\"constant\"/>", "unknown element <emiter> (did you mean <emitter>?)"},
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

// Mitsuba's alpha_u and alpha_v (conductors and dielectrics; rough plastic is isotropic only,
// so there they are unknown properties: an error, as in Mitsuba).
TEST(SceneLoader, AnisotropicRoughness) {
  Fixture f;
  Scene s;
  loadScene(f.scene(std::string(kSensor) + R"(
    <shape type="sphere"><bsdf type="roughconductor"><float name="alpha_u" value="0.05"/><float name="alpha_v" value="0.3"/></bsdf></shape>
    <shape type="sphere"><bsdf type="roughdielectric"><float name="alpha_v" value="0.2"/></bsdf></shape>)"),
            {}, s);
  const Bsdf &c = s.bsdfs[size_t(s.shapes[0].bsdf)], &d = s.bsdfs[size_t(s.shapes[1].bsdf)];
  EXPECT_TRUE(bsdfIsAnisotropic(c));
  EXPECT_NEAR(c.alpha, 0.05f, 1e-7f);
  EXPECT_NEAR(c.alphaV, 0.3f, 1e-7f);
  EXPECT_NEAR(microfacet(c).alphaY, 0.3f, 1e-7f);
  EXPECT_NEAR(d.alpha, 0.1f, 1e-7f) << "alpha_u defaults to 0.1, as in Mitsuba";
  EXPECT_NEAR(d.alphaV, 0.2f, 1e-7f);
  Scene plastic;
  try {
    loadScene(f.scene(std::string(kSensor) +
                      R"(<shape type="sphere"><bsdf type="roughplastic"><float name="alpha_u" value="0.2"/></bsdf></shape>)"),
              {}, plastic);
    ADD_FAILURE() << "roughplastic took alpha_u";
  } catch (const std::runtime_error& e) {
    // envgi asked for alpha_u itself (for the other BSDFs), but a name never suggests itself.
    EXPECT_NE(std::string(e.what()).find("bsdf 'roughplastic' has no property 'alpha_u' (did you mean 'alpha'?)"),
              std::string::npos)
        << e.what();
  }
}

// alpha_u and alpha_v as textures (Mitsuba's are textures too), each read as its luminance at
// the hit, and a value beside a texture; alpha beside a textured alpha_u is still refused.
TEST(SceneLoader, AnisotropicRoughnessTextured) {
  Fixture f;
  Scene s;
  loadScene(f.scene(std::string(kSensor) + R"(
    <texture type="checkerboard" id="checks"><rgb name="color0" value="0.3"/><rgb name="color1" value="0.05"/></texture>
    <shape type="sphere"><bsdf type="roughconductor"><ref id="checks" name="alpha_u"/><float name="alpha_v" value="0.4"/></bsdf></shape>
    <shape type="sphere"><bsdf type="roughdielectric"><ref id="checks" name="alpha_v"/></bsdf></shape>)"),
            {}, s);
  const Bsdf &c = s.bsdfs[size_t(s.shapes[0].bsdf)], &d = s.bsdfs[size_t(s.shapes[1].bsdf)];
  EXPECT_TRUE(bsdfIsAnisotropic(c));
  EXPECT_TRUE(bsdfIsAnisotropic(d));
  EXPECT_EQ(c.alphaTexture, 0);
  EXPECT_EQ(c.alphaVTexture, -1);
  EXPECT_EQ(d.alphaTexture, -1);
  EXPECT_EQ(d.alphaVTexture, 0);
  EXPECT_TRUE(bsdfHasTexture(d));
  const SceneView& v = s.view();
  // Checkerboard: color0 where u and v lie in the same half, color1 elsewhere.
  Bsdf at = v.bsdfAt(s.shapes[0].bsdf, Vec2f(0.25f, 0.25f));
  EXPECT_NEAR(at.alpha, 0.3f, 1e-5f);
  EXPECT_NEAR(at.alphaV, 0.4f, 1e-7f);
  EXPECT_NEAR(v.bsdfAt(s.shapes[0].bsdf, Vec2f(0.75f, 0.25f)).alpha, 0.05f, 1e-5f);
  at = v.bsdfAt(s.shapes[1].bsdf, Vec2f(0.75f, 0.25f));
  EXPECT_NEAR(at.alpha, 0.1f, 1e-7f) << "alpha_u keeps Mitsuba's default";
  EXPECT_NEAR(at.alphaV, 0.05f, 1e-5f);
  BsdfScratch scratch;
  SurfaceInteraction si;
  si.bsdf = s.shapes[1].bsdf;
  si.uv = Vec2f(0.25f, 0.75f);
  EXPECT_NEAR(v.bsdfAt(si, &scratch).alphaV, 0.05f, 1e-5f) << "the scratch form copies a textured alpha_v";

  Scene bad;
  try {
    loadScene(f.scene(std::string(kSensor) + R"(
      <shape type="sphere"><bsdf type="roughconductor"><float name="alpha" value="0.2"/>
        <texture type="checkerboard" name="alpha_u"/></bsdf></shape>)"),
              {}, bad);
    FAIL() << "alpha beside a textured alpha_u loaded";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("give either alpha or alpha_u and alpha_v, not both"), std::string::npos)
        << e.what();
  }
}

// A rough plastic reads its coat's tables (Mitsuba's roughplastic): those of its alpha, or those
// over all roughnesses where alpha is a texture, read at the hit's roughness; and `nonlinear`.
TEST(SceneLoader, RoughPlasticGetsItsCoatTables) {
  Fixture f;
  Scene s;
  loadScene(f.scene(std::string(kSensor) + R"(
    <texture type="checkerboard" id="checks"><rgb name="color0" value="0.3"/><rgb name="color1" value="0.05"/></texture>
    <shape type="sphere"><bsdf type="roughplastic"><float name="alpha" value="0.3"/></bsdf></shape>
    <shape type="sphere"><bsdf type="roughplastic"><ref id="checks" name="alpha"/>
      <boolean name="nonlinear" value="true"/></bsdf></shape>)"),
            {}, s);
  const Bsdf &plain = s.bsdfs[size_t(s.shapes[0].bsdf)], &textured = s.bsdfs[size_t(s.shapes[1].bsdf)];
  EXPECT_FALSE(plain.nonlinear);
  EXPECT_TRUE(textured.nonlinear);
  int nodes = 0;
  EXPECT_EQ(bsdfCoatTable(plain), roughCoatTable(0.3f, plain.ior, MicrofacetType::Beckmann, false, &nodes));
  EXPECT_EQ(plain.coatNodes, 1);
  ASSERT_NE(bsdfCoatTable(textured), nullptr);
  EXPECT_EQ(textured.coatNodes, kCoatAlphaNodes);
  // Where the texture says 0.3, the textured plastic is the plain one, to the tables' interpolation.
  Bsdf at = s.view().bsdfAt(s.shapes[1].bsdf, Vec2f(0.25f, 0.25f));
  EXPECT_NEAR(at.alpha, 0.3f, 1e-5f);
  Vec3f wo = normalize(Vec3f(0.3f, 0.1f, 0.8f)), wi = normalize(Vec3f(-0.5f, 0.2f, 0.6f));
  at.nonlinear = false;
  EXPECT_NEAR(bsdfEval(at, wo, wi).y, bsdfEval(plain, wo, wi).y, 0.01f * bsdfEval(plain, wo, wi).y);
}

TEST(SceneLoader, HarmlessUnsupportedElementsOnlyWarn) {
  Fixture f;
  Scene s;
  EXPECT_NO_THROW(loadScene(f.scene(std::string(kSensor) + R"(
    <emitter type="projector"/>
    <phase type="hg"/>
    <shape type="sphere"><float name="silhouette_sampling_weight" value="1"/></shape>
    <emitter type="spot"><texture type="checkerboard" name="texture"/></emitter>)"),
                            {}, s));
  ASSERT_EQ(s.deltaLights.size(), 1u) << "a spot's projected texture is left out; the spot stays";
}

// A property that no Mitsuba plugin of that type takes is an error, as Mitsuba's "Unreferenced
// property" is: a misspelt name would otherwise render without its value. One that Mitsuba's
// plugin takes and envgi leaves out only warns (above).
TEST(SceneLoader, APropertyMitsubaDoesNotKnowIsAnError) {
  Fixture f;
  const std::pair<const char*, const char*> bad[] = {
      {R"(<shape type="sphere"><float name="radus" value="2"/></shape>)",
       "shape 'sphere' has no property 'radus' (did you mean 'radius'?)"},
      {R"(<emitter type="constant"><rgb name="radiance" value="1"/><float name="scale" value="2"/></emitter>)",
       "emitter 'constant' has no property 'scale'"},
      // Said before the map is read: this one is not there at all.
      {R"(<emitter type="envmap"><string name="filename" value="missing.exr"/><float name="scal" value="2"/></emitter>)",
       "emitter 'envmap' has no property 'scal' (did you mean 'scale'?)"},
      // And before a mesh file is read: this one is not there either.
      {R"(<shape type="ply"><string name="filename" value="missing.ply"/><boolean name="face_normal" value="true"/></shape>)",
       "shape 'ply' has no property 'face_normal' (did you mean 'face_normals'?)"},
      {R"(<shape type="sphere"><bsdf type="diffuse"><rgb name="reflectence" value="0.5"/></bsdf></shape>)",
       "bsdf 'diffuse' has no property 'reflectence' (did you mean 'reflectance'?)"},
      {R"(<shape type="sphere"><bsdf type="roughconductor"><float name="alpha_x" value="0.1"/></bsdf></shape>)",
       "bsdf 'roughconductor' has no property 'alpha_x' (did you mean 'alpha_u'?)"},
      {R"(<integrator type="path"><integer name="maxdepth" value="3"/></integrator>)",
       "integrator 'path' has no property 'maxdepth' (did you mean 'max_depth'?)"},
      {R"(<integrator type="photon"><integer name="global_photon" value="1000"/></integrator>)",
       "integrator 'photon' has no property 'global_photon' (did you mean 'global_photons'?)"},
  };
  expectErrors(f, bad);
  // The sensor's own type counts: a thin lens takes an aperture, a pinhole does not.
  std::string pinhole = kSensor;
  const std::string fovTag = "<float name=\"fov\"";
  ASSERT_NE(pinhole.find(fovTag), std::string::npos);
  pinhole.insert(pinhole.find(fovTag), R"(<float name="aperture_radius" value="0.1"/>)");
  Scene s;
  EXPECT_THROW(loadScene(f.scene(pinhole), {}, s), std::runtime_error);
}

// The film's settings that change only how Mitsuba writes its file are accepted, each with its
// own type, so that a value of the wrong kind is an error rather than silently ignored.
TEST(SceneLoader, FilmFileSettingsAreReadWithTheirTypes) {
  auto withFilm = [](const std::string& extra) {
    std::string sensor = kSensor;
    const std::string film = "<film type=\"hdrfilm\">";
    sensor.replace(sensor.find(film), film.size(), film + extra);
    return sensor;
  };
  Fixture f;
  Scene s;
  EXPECT_NO_THROW(loadScene(f.scene(withFilm(R"(<boolean name="sample_border" value="true"/>
      <boolean name="banner" value="false"/><boolean name="high_quality_edges" value="true"/>
      <string name="pixel_format" value="rgba"/><string name="file_format" value="openexr"/>
      <string name="component_format" value="float16"/>)")),
                            {}, s));
  EXPECT_EQ(s.camera.width, 64);
  const std::pair<const char*, const char*> bad[] = {
      {R"(<string name="sample_border" value="true"/>)", "sample_border"},
      {R"(<boolean name="banner" value="maybe"/>)", "maybe"},
      {R"(<integer name="pixel_format" value="3"/>)", "pixel_format"},
  };
  for (const auto& [extra, expect] : bad) {
    std::string err = loadError(f.scene(withFilm(extra)));
    EXPECT_FALSE(err.empty()) << extra;
    EXPECT_NE(err.find(expect), std::string::npos) << extra << "\n got: " << err;
  }
}

TEST(SceneLoader, DirectionalAndPointEmitters) {
  Fixture f;
  Scene s;
  loadScene(f.scene(std::string(kSensor) + R"(
    <emitter type="directional"><vector name="direction" x="0" y="-2" z="0"/><rgb name="irradiance" value="3, 2, 1"/></emitter>
    <emitter type="directional"><transform name="to_world"><rotate x="1" angle="90"/></transform></emitter>
    <emitter type="point"><point name="position" x="1" y="2" z="3"/><rgb name="intensity" value="5"/></emitter>
    <emitter type="point"><transform name="to_world"><translate x="-1"/></transform></emitter>)"),
            {}, s);
  ASSERT_EQ(s.deltaLights.size(), 4u);
  const DeltaLight &sun = s.deltaLights[0], &rotated = s.deltaLights[1], &bulb = s.deltaLights[2],
                   &moved = s.deltaLights[3];
  EXPECT_FALSE(sun.point);
  EXPECT_NEAR(sun.v.y, -1.f, 1e-6f) << "the direction is normalised";
  EXPECT_EQ(sun.value.x, 3.f);
  // to_world's +z: rotated 90 degrees about x, (0, 0, 1) -> (0, -1, 0); irradiance defaults to 1.
  EXPECT_NEAR(rotated.v.y, -1.f, 1e-6f);
  EXPECT_NEAR(rotated.v.z, 0.f, 1e-6f);
  EXPECT_EQ(rotated.value.y, 1.f);
  EXPECT_TRUE(bulb.point);
  EXPECT_EQ(bulb.v.z, 3.f);
  EXPECT_EQ(bulb.value.y, 5.f);
  EXPECT_EQ(moved.v.x, -1.f) << "to_world's origin";
  s.finalize();
  EXPECT_EQ(s.view().deltaLightCount, 4);
  EXPECT_FLOAT_EQ(s.view().deltaSelectProb(), 1.f) << "the only kind of light";

  Scene spots;
  loadScene(f.scene(std::string(kSensor) + R"(
    <emitter type="spot"><transform name="to_world"><lookat origin="0, 2, 0" target="0, 0, 0" up="1, 0, 0"/></transform>
      <float name="cutoff_angle" value="30"/><rgb name="intensity" value="7"/></emitter>
    <emitter type="spot"/>)"),
            {}, spots);
  ASSERT_EQ(spots.deltaLights.size(), 2u);
  const DeltaLight& spot = spots.deltaLights[0];
  EXPECT_TRUE(spot.point);
  EXPECT_NEAR(spot.v.y, 2.f, 1e-6f);
  EXPECT_NEAR(spot.axis.y, -1.f, 1e-6f) << "lookat's +z points at the target";
  EXPECT_EQ(spot.value.x, 7.f);
  EXPECT_NEAR(spot.cosCutoff, std::cos(30.f * kPi / 180.f), 1e-6f);
  EXPECT_NEAR(spot.cosBeam, std::cos(22.5f * kPi / 180.f), 1e-6f) << "beam_width defaults to 3/4 of the cutoff";
  EXPECT_NEAR(spots.deltaLights[1].cosCutoff, std::cos(20.f * kPi / 180.f), 1e-6f) << "cutoff_angle defaults to 20";

  const std::pair<const char*, const char*> bad[] = {
      {R"(<emitter type="spot"><float name="cutoff_angle" value="20"/><float name="beam_width" value="25"/></emitter>)",
       "beam_width must be in (0, cutoff_angle]"},
      {R"(<emitter type="spot"><float name="cutoff_angle" value="0"/></emitter>)", "cutoff_angle must be in (0, 180]"},
      {R"(<emitter type="spot"><transform name="to_world"><scale value="1e20"/></transform></emitter>)",
       "'spot' emitter's to_world loses its axis"},
      {R"(<emitter type="directional"><vector name="direction" x="0" y="0" z="0"/></emitter>)", "non-zero, finite direction"},
      {R"(<emitter type="directional"><vector name="direction" x="0" y="1" z="0"/>
          <transform name="to_world"><translate x="1"/></transform></emitter>)", "'direction' or 'to_world', not both"},
      {R"(<emitter type="point"><rgb name="intensity" value="-1"/></emitter>)", "'intensity' must not be negative"},
      {R"(<emitter type="directional"><vector name="direction" x="1e30" y="0" z="0"/></emitter>)", "non-zero, finite direction"},
  };
  for (const auto& [body, expect] : bad) {
    std::string err = loadError(f.scene(std::string(body) + kSensor));
    EXPECT_NE(err.find(expect), std::string::npos) << body << "\n got: " << err;
  }
}

TEST(SceneLoader, TexturesNestedReferencedAndOnEveryColourTheyReplace) {
  Fixture f;
  Image img(2, 1);
  img.set(0, 0, Color(0.1f, 0.2f, 0.3f));
  img.set(1, 0, Color(0.4f, 0.5f, 0.6f));
  saveImage(img, f.dir.file("tex.exr"));
  Scene s;
  loadScene(f.scene(std::string(kSensor) + R"(
    <texture type="checkerboard" id="checks"><rgb name="color0" value="1, 0, 0"/>
      <transform name="to_uv"><scale x="4" y="2"/><translate x="0.5"/></transform></texture>
    <shape type="sphere"><bsdf type="diffuse"><texture type="bitmap" name="reflectance">
      <string name="filename" value="tex.exr"/><string name="wrap_mode" value="mirror"/>
      <string name="filter_type" value="nearest"/></texture></bsdf></shape>
    <shape type="sphere"><bsdf type="roughplastic"><ref id="checks" name="diffuse_reflectance"/>
      <ref id="checks" name="specular_reflectance"/></bsdf></shape>
    <shape type="sphere"><bsdf type="dielectric"><ref id="checks" name="specular_transmittance"/></bsdf></shape>
    <shape type="sphere"><bsdf type="roughconductor"><ref id="checks" name="alpha"/></bsdf></shape>
    <shape type="sphere"><bsdf type="conductor"><ref id="checks" name="eta"/></bsdf></shape>)"),
            {}, s);
  ASSERT_EQ(s.textures.size(), 2u);
  const TextureView& checks = s.textures[0].params;
  EXPECT_EQ(checks.type, TextureType::Checkerboard);
  EXPECT_EQ(checks.color0.x, 1.f);
  EXPECT_EQ(checks.color1.x, 0.2f);  // Mitsuba's default
  const float toUv[6] = {4.f, 0.f, 0.5f, 0.f, 2.f, 0.f};
  for (int i = 0; i < 6; ++i) EXPECT_NEAR(checks.toUv[i], toUv[i], 1e-6f) << i;
  const Texture& bitmap = s.textures[1];
  EXPECT_EQ(bitmap.params.wrap, TextureWrap::Mirror);
  EXPECT_FALSE(bitmap.params.bilinear);
  ASSERT_EQ(bitmap.texels.size(), 2u);
  EXPECT_NEAR(bitmap.texels[1].z, 0.6f, 1e-6f);
  auto bsdf = [&](size_t shape) { return s.bsdfs[size_t(s.shapes[shape].bsdf)]; };
  EXPECT_EQ(bsdf(0).reflectanceTexture, 1);
  EXPECT_EQ(bsdf(1).reflectanceTexture, 0);
  EXPECT_EQ(bsdf(1).specularReflectanceTexture, 0);
  // The coat's sampling weight from the textures' means, as in Mitsuba: both are the checks'
  // mean, so half (the untextured defaults would give 1 / (1 + 0.5)).
  EXPECT_NEAR(bsdf(1).specularSamplingWeight, 0.5f, 1e-5f);
  EXPECT_EQ(bsdf(2).specularTransmittanceTexture, 0);
  EXPECT_EQ(bsdf(2).reflectanceTexture, -1);
  EXPECT_EQ(bsdf(3).alphaTexture, 0);
  // A texture for a property read as a constant warns and leaves it alone.
  EXPECT_EQ(bsdf(4).reflectanceTexture, -1);
  EXPECT_EQ(bsdf(4).specularReflectanceTexture, -1);
  EXPECT_EQ(bsdf(4).alphaTexture, -1);
  EXPECT_TRUE(bsdf(4).perfectMirror) << "eta keeps its default (material none)";
  // The view resolves them at a hit's uv: texel 1 of the bitmap is u in [0.5, 1).
  const SceneView& v = s.view();
  EXPECT_NEAR(v.bsdfAt(s.shapes[0].bsdf, Vec2f(0.75f, 0.5f)).reflectance.y, 0.5f, 1e-6f);
  EXPECT_NEAR(v.bsdfAt(s.shapes[0].bsdf, Vec2f(1.25f, 0.5f)).reflectance.y, 0.5f, 1e-6f) << "mirrored";
  // Checks at uv (0.1, 0.1): to_uv gives (0.9, 0.2), squares (1, 0): odd, color1.
  EXPECT_NEAR(v.bsdfAt(s.shapes[1].bsdf, Vec2f(0.1f, 0.1f)).reflectance.x, 0.2f, 1e-6f);
  EXPECT_NEAR(v.bsdfAt(s.shapes[1].bsdf, Vec2f(0.15f, 0.1f)).specularReflectance.x, 1.f, 1e-6f);  // (1.1, 0.2)
  // A colour texture as roughness reads its luminance: color0 (1, 0, 0) is 0.2126.
  EXPECT_NEAR(v.bsdfAt(s.shapes[3].bsdf, Vec2f(0.15f, 0.1f)).alpha, 0.2126f, 1e-4f);
  EXPECT_NEAR(v.bsdfAt(s.shapes[3].bsdf, Vec2f(0.1f, 0.1f)).alpha, 0.2f, 1e-4f);
}

// uv as Mitsuba makes them: v flipped in OBJ and PLY files (unless flip_tex_coords is false),
// and on a sphere u the azimuth about its local z from local x, v the polar angle from +z
// (computed where a texture reads them: these spheres are textured).
TEST(SceneLoader, SurfaceCoordinatesFollowMitsuba) {
  Fixture f;
  f.write("uv.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0.25 0.125\nvt 1 0\nvt 0 1\nf 1/1 2/2 3/3\n");
  Scene s;
  loadScene(f.scene(std::string(kSensor) + R"(
    <shape type="obj"><string name="filename" value="uv.obj"/></shape>
    <shape type="obj"><string name="filename" value="uv.obj"/><boolean name="flip_tex_coords" value="false"/></shape>
    <bsdf type="diffuse" id="checks"><texture type="checkerboard" name="reflectance"/></bsdf>
    <shape type="sphere"><ref id="checks"/></shape>
    <shape type="sphere"><transform name="to_world"><rotate z="1" angle="90"/><translate x="10"/></transform>
      <ref id="checks"/></shape>)"),
            {}, s);
  EXPECT_NEAR(s.meshes[0].uvs[0].y, 0.875f, 1e-6f);
  EXPECT_NEAR(s.meshes[1].uvs[0].y, 0.125f, 1e-6f);
  const SceneView& v = s.view();
  auto sphereUv = [&](int sphere, Vec3f center, Vec3f dir) {
    Ray r{center - dir * 5.f, dir, INFINITY};
    Hit h;
    h.t = 4.f;
    h.geomId = v.meshCount + sphere;
    h.primId = 0;
    return v.interaction(r, h).uv;
  };
  struct Case {
    Vec3f dir;  // the ray's direction: it hits the sphere at -dir
    float u, v;
  } cases[] = {{{0, 0, -1}, 0.f, 0.f}, {{-1, 0, 0}, 0.f, 0.5f}, {{0, -1, 0}, 0.25f, 0.5f},
               {{1, 0, 0}, 0.5f, 0.5f}, {{0, 1, 0}, 0.75f, 0.5f}, {{0, 0, 1}, 0.f, 1.f}};
  for (const Case& c : cases) {
    Vec2f uv = sphereUv(0, Vec3f(0.f), c.dir);
    if (c.v > 0.f && c.v < 1.f) {  // u is undefined at the poles
      EXPECT_NEAR(std::remainder(uv.x - c.u, 1.f), 0.f, 1e-5f) << c.dir.x << c.dir.y << c.dir.z;
    }
    EXPECT_NEAR(uv.y, c.v, 1e-5f) << c.dir.x << c.dir.y << c.dir.z;
  }
  // Turned a quarter about z: world +y is the sphere's local +x (u = 0, which is also 1).
  EXPECT_NEAR(std::remainder(sphereUv(1, Vec3f(10.f, 0.f, 0.f), Vec3f(0.f, -1.f, 0.f)).x, 1.f), 0.f, 1e-5f);
  EXPECT_NEAR(sphereUv(1, Vec3f(10.f, 0.f, 0.f), Vec3f(1.f, 0.f, 0.f)).x, 0.25f, 1e-5f);
}

TEST(SceneLoader, TextureErrorsNameTheLineAndTheProblem) {
  Fixture f;
  Image nan(1, 1);
  nan.rgb[1] = NAN;
  saveImage(nan, f.dir.file("nan.pfm"));
  struct Case {
    std::string body, expect;
  } cases[] = {
      {R"(<texture type="wood" id="t"/>)", "s.xml:2: unknown texture type 'wood' (bitmap, checkerboard)"},
      {R"(<texture type="bitmap" id="t"/>)", "bitmap needs a 'filename'"},
      {R"(<texture type="bitmap" id="t"><string name="filename" value="none.png"/></texture>)", "cannot open image"},
      {R"(<texture type="bitmap" id="t"><string name="filename" value="nan.pfm"/></texture>)",
       "has a negative, NaN or infinite texel"},
      {R"(<texture type="bitmap" id="t"><string name="filename" value="sky.exr"/><string name="wrap_mode" value="tile"/></texture>)",
       "wrap_mode must be repeat, mirror or clamp, not 'tile'"},
      {R"(<texture type="checkerboard" id="t"><texture type="checkerboard" name="color0"/></texture>)",
       "s.xml:2: unexpected <texture> in <texture>"},
      {R"(<texture type="checkerboard" id="t"/><texture type="checkerboard" id="t"/>)", "duplicate texture id 't'"},
      {R"(<bsdf type="diffuse"><ref id="nothing" name="reflectance"/></bsdf>)", "unknown texture id 'nothing'"},
      {R"(<bsdf type="diffuse"><rgb name="reflectance" value="0.5"/>
          <texture type="checkerboard" name="reflectance"/></bsdf>)",
       "s.xml:3: property 'reflectance' given twice"},
      {R"(<bsdf type="diffuse"><texture type="checkerboard"/></bsdf>)", "<texture> needs a 'name' attribute"},
      {R"(<emitter type="constant"><bsdf type="diffuse"/></emitter>)", "s.xml:2: unexpected <bsdf> in <emitter>"},
  };
  for (const Case& c : cases) {
    std::string err = loadError(f.scene(c.body + std::string(kSensor)));
    EXPECT_NE(err.find(c.expect), std::string::npos) << "for " << c.body << "\n got: " << err;
  }
}

TEST(SceneLoader, EnvmapReadsALightProbe) {
  // layout="angular" resamples the square probe to lat-long as it is read; the default reads the
  // file as lat-long.
  Fixture f;
  Image probe(16, 16);
  for (int y = 0; y < 16; ++y)
    for (int x = 0; x < 16; ++x) probe.set(x, y, Color(float(x), float(y), 1.f));
  saveImage(probe, f.dir.file("probe.exr"));
  for (const char* layout : {"angular", "mirrorball"}) {
    Scene s;
    loadScene(f.scene(std::string(kSensor) + R"(<emitter type="envmap"><string name="filename" value="probe.exr"/>
      <string name="layout" value=")" + layout + R"("/></emitter>)"),
              {}, s);
    ASSERT_TRUE(s.env);
    Image expect = probeToLatLong(probe, parseProbeLayout(layout));
    EXPECT_EQ(s.env->image().width, 32);
    EXPECT_EQ(s.env->image().rgb, expect.rgb) << layout;
  }
  Scene plain;
  loadScene(f.scene(std::string(kSensor) + R"(<emitter type="envmap"><string name="filename" value="probe.exr"/></emitter>)"), {},
            plain);
  EXPECT_EQ(plain.env->image().width, 16) << "without a layout the file is the lat-long map";
}

// Mitsuba's normalmap adapter: its texture nested or referenced, its BSDF nested or
// referenced (then copied, so the referenced one stays unmapped), inside twosided, with its two
// switches; the map's value at a hit becomes the unit normal the BSDF is evaluated about, and
// meshes under it build their frame along dp/du.
TEST(SceneLoader, NormalMap) {
  Fixture f;
  Scene s;
  loadScene(f.scene(std::string(kSensor) + R"(
    <texture type="checkerboard" id="tilt"><rgb name="color0" value="0.5, 0.5, 1"/><rgb name="color1" value="1, 0.5, 0.5"/></texture>
    <bsdf type="roughplastic" id="coat"><float name="alpha" value="0.2"/></bsdf>
    <shape type="sphere"><bsdf type="normalmap"><ref id="tilt" name="normalmap"/><ref id="coat"/></bsdf></shape>
    <shape type="ply"><string name="filename" value="tri.ply"/>
      <bsdf type="twosided"><bsdf type="normalmap">
        <texture type="checkerboard" name="normalmap"><rgb name="color0" value="0.5"/></texture>
        <boolean name="flip_invalid_normals" value="false"/><boolean name="use_shadowing_function" value="false"/>
        <bsdf type="diffuse"/></bsdf></bsdf></shape>
    <shape type="sphere"><ref id="coat"/></shape>)"),
            {}, s);
  const Bsdf &a = s.bsdfs[size_t(s.shapes[0].bsdf)], &b = s.bsdfs[size_t(s.shapes[1].bsdf)];
  EXPECT_EQ(a.type, BsdfType::RoughPlastic);
  EXPECT_EQ(a.normalMapTexture, 0);
  EXPECT_TRUE(a.flipInvalidNormals);
  EXPECT_TRUE(a.bumpShadowing);
  EXPECT_FALSE(bsdfIsNormalMapped(s.bsdfs[size_t(s.shapes[2].bsdf)])) << "the referenced BSDF itself is unmapped";
  EXPECT_EQ(b.type, BsdfType::Diffuse);
  EXPECT_TRUE(b.twoSided);
  EXPECT_EQ(b.normalMapTexture, 1);
  EXPECT_FALSE(b.flipInvalidNormals);
  EXPECT_FALSE(b.bumpShadowing);
  EXPECT_TRUE(bsdfHasTexture(a));
  EXPECT_TRUE(s.view().meshes[0].anisotropic) << "a normal-mapped mesh builds its frame along dp/du";
  // color0 (0.5, 0.5, 1) decodes to +z; color1 (1, 0.5, 0.5) to +x; (0.5, 0.5, 0.5) to no
  // direction, which leaves the frame alone.
  const SceneView& v = s.view();
  Vec3f up = v.bsdfAt(s.shapes[0].bsdf, Vec2f(0.25f, 0.25f)).mappedNormal;
  Vec3f side = v.bsdfAt(s.shapes[0].bsdf, Vec2f(0.75f, 0.25f)).mappedNormal;
  EXPECT_NEAR(up.z, 1.f, 1e-6f);
  EXPECT_NEAR(side.x, 1.f, 1e-6f);
  EXPECT_NEAR(side.z, 0.f, 1e-6f);
  EXPECT_EQ(v.bsdfAt(s.shapes[1].bsdf, Vec2f(0.25f, 0.25f)).mappedNormal.z, 1.f);

  const std::pair<const char*, const char*> bad[] = {
      {R"(<shape type="sphere"><bsdf type="normalmap"><bsdf type="diffuse"/></bsdf></shape>)",
       "normalmap needs a texture named 'normalmap'"},
      {R"(<shape type="sphere"><bsdf type="normalmap"><texture type="checkerboard" name="normalmap"/></bsdf></shape>)",
       "normalmap needs a nested <bsdf>"},
      {R"(<shape type="sphere"><bsdf type="normalmap"><texture type="checkerboard" name="normal"/><bsdf type="diffuse"/></bsdf></shape>)",
       "normalmap has no texture property 'normal'"},
      {R"(<shape type="sphere"><bsdf type="normalmap"><texture type="checkerboard" name="normalmap"/><bsdf type="diffuse"/><bsdf type="diffuse"/></bsdf></shape>)",
       "normalmap takes one nested BSDF"},
      {R"(<shape type="sphere"><bsdf type="normalmap"><texture type="checkerboard" name="normalmap"/><bsdf type="normalmap"><texture type="checkerboard" name="normalmap"/><bsdf type="diffuse"/></bsdf></bsdf></shape>)",
       "a normalmap around a normalmap or bumpmap is not supported"},
      {R"(<shape type="sphere"><bsdf type="normalmap"><texture type="checkerboard" name="normalmap"/><ref id="nothing"/></bsdf></shape>)",
       "unknown BSDF or texture id 'nothing'"},
      {R"(<shape type="sphere"><bsdf type="normalmap"><texture type="checkerboard" name="normalmap"/><boolean name="flip_invalid_normal" value="true"/><bsdf type="diffuse"/></bsdf></shape>)",
       "bsdf 'normalmap' has no property 'flip_invalid_normal' (did you mean 'flip_invalid_normals'?)"},
  };
  expectErrors(f, bad);
}

// Mitsuba's bumpmap adapter: one texture of any name (the height), its scale, the same two
// switches as normalmap; errors for a missing or second texture, a bump map around a normal
// map, a misspelt property.
TEST(SceneLoader, BumpMap) {
  Fixture f;
  Scene s;
  loadScene(f.scene(std::string(kSensor) + R"(
    <shape type="sphere"><bsdf type="bumpmap"><texture type="checkerboard" name="height"/>
      <float name="scale" value="0.25"/><boolean name="use_shadowing_function" value="false"/>
      <bsdf type="roughplastic"/></bsdf></shape>
    <shape type="ply"><string name="filename" value="tri.ply"/>
      <bsdf type="bumpmap"><texture type="checkerboard"/><bsdf type="diffuse"/></bsdf></shape>)"),
            {}, s);
  const Bsdf &a = s.bsdfs[size_t(s.shapes[0].bsdf)], &b = s.bsdfs[size_t(s.shapes[1].bsdf)];
  EXPECT_EQ(a.type, BsdfType::RoughPlastic);
  EXPECT_EQ(a.bumpTexture, 0);
  EXPECT_EQ(a.normalMapTexture, -1);
  EXPECT_FLOAT_EQ(a.bumpScale, 0.25f);
  EXPECT_TRUE(a.flipInvalidNormals);
  EXPECT_FALSE(a.bumpShadowing);
  EXPECT_EQ(b.bumpTexture, 1);
  EXPECT_FLOAT_EQ(b.bumpScale, 1.f);
  EXPECT_TRUE(b.bumpShadowing);
  EXPECT_TRUE(s.view().meshes[0].anisotropic) << "a bump-mapped mesh builds its frame along dp/du";

  const std::pair<const char*, const char*> bad[] = {
      {R"(<shape type="sphere"><bsdf type="bumpmap"><bsdf type="diffuse"/></bsdf></shape>)",
       "bumpmap needs a nested texture (its height)"},
      {R"(<shape type="sphere"><bsdf type="bumpmap"><texture type="checkerboard"/></bsdf></shape>)",
       "bumpmap needs a nested <bsdf>"},
      {R"(<shape type="sphere"><bsdf type="bumpmap"><texture type="checkerboard"/><texture type="checkerboard"/><bsdf type="diffuse"/></bsdf></shape>)",
       "bumpmap takes one texture"},
      {R"(<shape type="sphere"><bsdf type="bumpmap"><texture type="checkerboard"/><bsdf type="normalmap"><texture type="checkerboard" name="normalmap"/><bsdf type="diffuse"/></bsdf></bsdf></shape>)",
       "a bumpmap around a normalmap or bumpmap is not supported"},
      {R"(<shape type="sphere"><bsdf type="bumpmap"><texture type="checkerboard"/><float name="scales" value="2"/><bsdf type="diffuse"/></bsdf></shape>)",
       "bsdf 'bumpmap' has no property 'scales' (did you mean 'scale'?)"},
  };
  expectErrors(f, bad);
}

// Mitsuba's cylinder: p0 (the origin), p1 (+z) and radius (1) unless given, then to_world; an
// open tube tessellated about its axis; a radius that is not positive, or p0 = p1, is an error
// with the line, and a property of another shape is Mitsuba's error.
TEST(SceneLoader, Cylinder) {
  Fixture f;
  Scene s;
  loadScene(f.scene(std::string(kSensor) + R"(
    <shape type="cylinder"><point name="p0" x="0" y="-1" z="0"/><point name="p1" x="0" y="2" z="0"/>
      <float name="radius" value="0.5"/><transform name="to_world"><translate x="3"/></transform></shape>
    <shape type="cylinder"/>)"),
            {}, s);
  ASSERT_EQ(s.meshes.size(), 2u);
  for (const Vec3f& p : s.meshes[0].positions) {
    EXPECT_NEAR(std::hypot(p.x - 3.f, p.z), 0.5f, 1e-5f);
    EXPECT_TRUE(std::fabs(p.y + 1.f) < 1e-5f || std::fabs(p.y - 2.f) < 1e-5f);
  }
  for (const Vec3f& p : s.meshes[1].positions) {
    EXPECT_NEAR(std::hypot(p.x, p.y), 1.f, 1e-5f);
    EXPECT_TRUE(p.z == 0.f || std::fabs(p.z - 1.f) < 1e-6f);
  }
  const std::pair<const char*, const char*> bad[] = {
      {R"(<shape type="cylinder"><float name="radius" value="0"/></shape>)", "cylinder radius must be positive"},
      {R"(<shape type="cylinder"><point name="p1" x="0" y="0" z="0"/></shape>)", "p0 and p1 must be two different points"},
      {R"(<shape type="cylinder"><point name="center" x="0" y="0" z="0"/></shape>)",
       "shape 'cylinder' has no property 'center'"},
  };
  expectErrors(f, bad);
}

// Mitsuba's blendbsdf: two nested BSDFs in the order given (a <ref> copied), `weight` (0.5
// unless given) a number or a texture named weight; twosided and a normal map around a blend
// reach every material it may choose, a ref'd blend's copy leaving the original as it was; a
// mask goes around it. Errors: one BSDF or three, a weight out of [0, 1] or given twice, a
// texture of another name, a mask inside.
TEST(SceneLoader, BlendBsdf) {
  Fixture f;
  Scene s;
  loadScene(f.scene(std::string(kSensor) + R"(
    <bsdf type="blendbsdf" id="mix"><float name="weight" value="0.25"/>
      <bsdf type="diffuse"><rgb name="reflectance" value="0.2"/></bsdf>
      <bsdf type="roughconductor"/></bsdf>
    <shape type="sphere"><ref id="mix"/></shape>
    <shape type="sphere"><bsdf type="twosided"><ref id="mix"/></bsdf></shape>
    <shape type="sphere"><bsdf type="blendbsdf"><texture type="checkerboard" name="weight"/>
      <ref id="mix"/><bsdf type="twosided"><bsdf type="plastic"/></bsdf></bsdf></shape>
    <shape type="sphere"><bsdf type="mask"><float name="opacity" value="0.4"/><bsdf type="blendbsdf">
      <bsdf type="diffuse"/><bsdf type="conductor"/></bsdf></bsdf></shape>)"),
            {}, s);
  auto at = [&](size_t shape) -> const Bsdf& { return s.bsdfs[size_t(s.shapes[shape].bsdf)]; };
  const Bsdf& mix = at(0);
  ASSERT_TRUE(bsdfIsBlend(mix));
  EXPECT_FLOAT_EQ(mix.blendWeight, 0.25f);
  EXPECT_EQ(s.bsdfs[size_t(mix.blend0)].type, BsdfType::Diffuse);
  EXPECT_FLOAT_EQ(s.bsdfs[size_t(mix.blend0)].reflectance.x, 0.2f);
  EXPECT_EQ(s.bsdfs[size_t(mix.blend1)].type, BsdfType::RoughConductor);
  EXPECT_FALSE(s.bsdfs[size_t(mix.blend0)].twoSided) << "the twosided copy left the original one-sided";
  const Bsdf& two = at(1);
  ASSERT_TRUE(bsdfIsBlend(two));
  EXPECT_NE(two.blend0, mix.blend0);
  EXPECT_TRUE(s.bsdfs[size_t(two.blend0)].twoSided);
  EXPECT_TRUE(s.bsdfs[size_t(two.blend1)].twoSided);
  const Bsdf& textured = at(2);
  EXPECT_GE(textured.blendWeightTexture, 0);
  EXPECT_TRUE(bsdfIsBlend(s.bsdfs[size_t(textured.blend0)])) << "a blend in a blend";
  EXPECT_EQ(s.bsdfs[size_t(textured.blend1)].type, BsdfType::Plastic);
  const Bsdf& masked = at(3);
  EXPECT_TRUE(bsdfIsBlend(masked));
  EXPECT_FLOAT_EQ(masked.opacity, 0.4f);
  // A normal map around a blend maps both of its materials.
  Scene n;
  loadScene(f.scene(std::string(kSensor) + R"(
    <texture type="bitmap" id="normals"><string name="filename" value="sky.exr"/><boolean name="raw" value="true"/></texture>
    <shape type="sphere"><bsdf type="normalmap"><ref id="normals" name="normalmap"/>
      <bsdf type="blendbsdf"><bsdf type="diffuse"/><bsdf type="roughplastic"/></bsdf></bsdf></shape>)"),
            {}, n);
  const Bsdf& nb = n.bsdfs[size_t(n.shapes[0].bsdf)];
  ASSERT_TRUE(bsdfIsBlend(nb));
  EXPECT_GE(n.bsdfs[size_t(nb.blend0)].normalMapTexture, 0);
  EXPECT_GE(n.bsdfs[size_t(nb.blend1)].normalMapTexture, 0);

  const std::pair<const char*, const char*> bad[] = {
      {R"(<shape type="sphere"><bsdf type="blendbsdf"><bsdf type="diffuse"/></bsdf></shape>)",
       "blendbsdf needs 2 nested BSDFs"},
      {R"(<shape type="sphere"><bsdf type="blendbsdf"><bsdf type="diffuse"/><bsdf type="diffuse"/><bsdf type="diffuse"/></bsdf></shape>)",
       "blendbsdf takes 2 nested BSDFs"},
      {R"(<shape type="sphere"><bsdf type="blendbsdf"><float name="weight" value="1.5"/><bsdf type="diffuse"/><bsdf type="diffuse"/></bsdf></shape>)",
       "blendbsdf's weight must be within [0, 1]"},
      {R"(<shape type="sphere"><bsdf type="blendbsdf"><texture type="checkerboard" name="opacity"/><bsdf type="diffuse"/><bsdf type="diffuse"/></bsdf></shape>)",
       "blendbsdf has no texture property 'opacity'"},
      {R"(<shape type="sphere"><bsdf type="blendbsdf"><float name="weight" value="0.5"/><texture type="checkerboard" name="weight"/><bsdf type="diffuse"/><bsdf type="diffuse"/></bsdf></shape>)",
       "property 'weight' given twice"},
      {R"(<shape type="sphere"><bsdf type="blendbsdf"><bsdf type="mask"><bsdf type="diffuse"/></bsdf><bsdf type="diffuse"/></bsdf></shape>)",
       "a mask inside a blendbsdf is not supported"},
      {R"(<shape type="sphere"><bsdf type="blendbsdf"><bsdf type="diffuse"/><bsdf type="blendbsdf"><bsdf type="diffuse"/>
         <bsdf type="mask"><bsdf type="blendbsdf"><bsdf type="diffuse"/><bsdf type="diffuse"/></bsdf></bsdf></bsdf></bsdf></shape>)",
       "a mask inside a blendbsdf is not supported"},
      {R"(<shape type="sphere"><bsdf type="blendbsdf"><float name="wieght" value="0.5"/><bsdf type="diffuse"/><bsdf type="diffuse"/></bsdf></shape>)",
       "bsdf 'blendbsdf' has no property 'wieght' (did you mean 'weight'?)"},
  };
  expectErrors(f, bad);
}

// Mitsuba's mask: opacity as a number (0.5 unless given) or a texture named opacity, around
// any BSDF (twosided included, either way round); errors for a wrong name, a value out of
// [0, 1], two opacities, a missing BSDF, a mask on an area light.
TEST(SceneLoader, Mask) {
  Fixture f;
  Scene s;
  loadScene(f.scene(std::string(kSensor) + R"(
    <shape type="sphere"><bsdf type="mask"><float name="opacity" value="0.25"/><bsdf type="roughplastic"/></bsdf></shape>
    <shape type="sphere"><bsdf type="mask"><bsdf type="twosided"><bsdf type="diffuse"/></bsdf></bsdf></shape>
    <shape type="ply"><string name="filename" value="tri.ply"/>
      <bsdf type="twosided"><bsdf type="mask"><texture type="checkerboard" name="opacity"/><bsdf type="diffuse"/></bsdf></bsdf></shape>)"),
            {}, s);
  const Bsdf &a = s.bsdfs[size_t(s.shapes[0].bsdf)], &b = s.bsdfs[size_t(s.shapes[1].bsdf)],
             &c = s.bsdfs[size_t(s.shapes[2].bsdf)];
  EXPECT_EQ(a.type, BsdfType::RoughPlastic);
  EXPECT_FLOAT_EQ(a.opacity, 0.25f);
  EXPECT_EQ(a.opacityTexture, -1);
  EXPECT_FLOAT_EQ(b.opacity, 0.5f);
  EXPECT_TRUE(b.twoSided);
  EXPECT_EQ(c.opacityTexture, 0);
  EXPECT_TRUE(c.twoSided);
  EXPECT_TRUE(bsdfIsMasked(a) && bsdfIsMasked(b) && bsdfIsMasked(c));
  EXPECT_TRUE(s.view().hasMasks);

  const std::pair<const char*, const char*> bad[] = {
      {R"(<shape type="sphere"><bsdf type="mask"><float name="opacity" value="1.5"/><bsdf type="diffuse"/></bsdf></shape>)",
       "mask's opacity must be within [0, 1], not 1.5"},
      {R"(<shape type="sphere"><bsdf type="mask"><float name="opacity" value="0.5"/></bsdf></shape>)",
       "mask needs a nested <bsdf>"},
      {R"(<shape type="sphere"><bsdf type="mask"><texture type="checkerboard" name="alpha"/><bsdf type="diffuse"/></bsdf></shape>)",
       "mask has no texture property 'alpha' (its texture is named 'opacity')"},
      {R"(<shape type="sphere"><bsdf type="mask"><float name="opacity" value="0.5"/><texture type="checkerboard" name="opacity"/><bsdf type="diffuse"/></bsdf></shape>)",
       "property 'opacity' given twice"},
      {R"(<shape type="sphere"><bsdf type="mask"><bsdf type="mask"><bsdf type="diffuse"/></bsdf></bsdf></shape>)",
       "a mask around a mask is not supported"},
      {R"(<shape type="sphere"><bsdf type="mask"><float name="opacty" value="0.5"/><bsdf type="diffuse"/></bsdf></shape>)",
       "bsdf 'mask' has no property 'opacty' (did you mean 'opacity'?)"},
      {R"(<shape type="sphere"><emitter type="area"><rgb name="radiance" value="1"/></emitter><bsdf type="mask"><bsdf type="diffuse"/></bsdf></shape>)",
       "an area emitter's shape cannot have a mask BSDF"},
  };
  expectErrors(f, bad);
}

// Mitsuba 3's principled BSDF: its properties as Mitsuba names them, eta from specular where
// eta is not given, textures for base_color, roughness and metallic, and errors for values out
// of range, for eta and specular together and for a misspelt name.
TEST(SceneLoader, Principled) {
  Fixture f;
  Scene s;
  loadScene(f.scene(std::string(kSensor) + R"(
    <shape type="sphere"><bsdf type="principled">
      <rgb name="base_color" value="0.8, 0.2, 0.1"/><float name="roughness" value="0.3"/>
      <float name="metallic" value="0.7"/><float name="anisotropic" value="0.4"/><float name="spec_trans" value="0.2"/>
      <float name="spec_tint" value="0.1"/><float name="sheen" value="0.6"/><float name="sheen_tint" value="0.5"/>
      <float name="flatness" value="0.25"/><float name="clearcoat" value="0.9"/><float name="clearcoat_gloss" value="0.8"/>
      <float name="eta" value="1.33"/><float name="clearcoat_sampling_rate" value="2"/></bsdf></shape>
    <shape type="sphere"><bsdf type="principled">
      <texture type="checkerboard" name="roughness"><rgb name="color0" value="0.2"/><rgb name="color1" value="0.9"/></texture>
      <texture type="checkerboard" name="metallic"><rgb name="color0" value="1"/><rgb name="color1" value="0"/></texture>
      <texture type="checkerboard" name="base_color"><rgb name="color0" value="0.1, 0.2, 0.3"/></texture>
      <float name="specular" value="0.5"/></bsdf></shape>)"),
            {}, s);
  const Bsdf &a = s.bsdfs[size_t(s.shapes[0].bsdf)], &b = s.bsdfs[size_t(s.shapes[1].bsdf)];
  ASSERT_EQ(a.type, BsdfType::Principled);
  EXPECT_EQ(a.reflectance.x, 0.8f);
  EXPECT_EQ(a.principled.roughness, 0.3f);
  EXPECT_EQ(a.principled.metallic, 0.7f);
  EXPECT_EQ(a.principled.anisotropic, 0.4f);
  EXPECT_EQ(a.principled.specTrans, 0.2f);
  EXPECT_EQ(a.principled.specTint, 0.1f);
  EXPECT_EQ(a.principled.sheen, 0.6f);
  EXPECT_EQ(a.principled.sheenTint, 0.5f);
  EXPECT_EQ(a.principled.flatness, 0.25f);
  EXPECT_EQ(a.principled.clearcoat, 0.9f);
  EXPECT_EQ(a.principled.clearcoatGloss, 0.8f);
  EXPECT_EQ(a.principled.clearcoatRate, 2.f);
  EXPECT_EQ(a.ior, 1.33f);
  EXPECT_TRUE(bsdfTransmits(a));
  EXPECT_TRUE(bsdfNeedsTangentFrame(a)) << "anisotropic: the lobe follows dp/du";
  EXPECT_NEAR(b.ior, 1.5f, 1e-6f);
  EXPECT_FALSE(bsdfTransmits(b));
  EXPECT_TRUE(bsdfHasTexture(b));
  const SceneView& v = s.view();
  Bsdf t0 = v.bsdfAt(s.shapes[1].bsdf, Vec2f(0.25f, 0.25f)), t1 = v.bsdfAt(s.shapes[1].bsdf, Vec2f(0.75f, 0.25f));
  EXPECT_NEAR(t0.principled.roughness, 0.2f, 1e-6f);
  EXPECT_NEAR(t1.principled.roughness, 0.9f, 1e-6f);
  EXPECT_NEAR(t0.principled.metallic, 1.f, 1e-6f);
  EXPECT_NEAR(t1.principled.metallic, 0.f, 1e-6f);
  EXPECT_NEAR(t0.reflectance.z, 0.3f, 1e-6f);
  // Under Mitsuba's normalmap adapter, as any BSDF.
  Scene m;
  loadScene(f.scene(std::string(kSensor) + R"(
    <shape type="sphere"><bsdf type="normalmap">
      <texture type="checkerboard" name="normalmap"><rgb name="color0" value="0.5, 0.5, 1"/></texture>
      <bsdf type="principled"><float name="clearcoat" value="1"/></bsdf></bsdf></shape>)"),
            {}, m);
  const Bsdf& mapped = m.bsdfs[size_t(m.shapes[0].bsdf)];
  EXPECT_EQ(mapped.type, BsdfType::Principled);
  EXPECT_TRUE(bsdfIsNormalMapped(mapped));
  EXPECT_EQ(mapped.principled.clearcoat, 1.f);

  const std::pair<const char*, const char*> bad[] = {
      {R"(<shape type="sphere"><bsdf type="principled"><float name="metallic" value="1.5"/></bsdf></shape>)",
       "principled 'metallic' must lie in [0, 1] (got 1.5)"},
      {R"(<shape type="sphere"><bsdf type="principled"><float name="roughness" value="-0.1"/></bsdf></shape>)",
       "principled 'roughness' must lie in [0, 1] (got -0.1)"},
      {R"(<shape type="sphere"><bsdf type="principled"><float name="eta" value="1.4"/><float name="specular" value="0.3"/></bsdf></shape>)",
       "principled takes 'eta' or 'specular', not both"},
      {R"(<shape type="sphere"><bsdf type="principled"><float name="eta" value="0"/></bsdf></shape>)",
       "principled 'eta' must be > 0 (got 0)"},
      {R"(<shape type="sphere"><bsdf type="principled"><float name="specular" value="20"/></bsdf></shape>)",
       "principled 'specular' must lie in [0, 12.5) (got 20)"},
      {R"(<shape type="sphere"><bsdf type="principled"><float name="clearcoat_sampling_rate" value="-1"/></bsdf></shape>)",
       "principled 'clearcoat_sampling_rate' must be finite and >= 0 (got -1)"},
      {R"(<shape type="sphere"><bsdf type="principled"><float name="metalic" value="1"/></bsdf></shape>)",
       "bsdf 'principled' has no property 'metalic' (did you mean 'metallic'?)"},
  };
  expectErrors(f, bad);
}

namespace {
// Bit-exact: the instance must place the very floats the plain shape gets.
::testing::AssertionResult sameVec(Vec3f a, Vec3f b) {
  if (a.x == b.x && a.y == b.y && a.z == b.z) return ::testing::AssertionSuccess();
  return ::testing::AssertionFailure() << "(" << a.x << ", " << a.y << ", " << a.z << ") != (" << b.x << ", " << b.y
                                       << ", " << b.z << ")";
}
}  // namespace

// Mitsuba's shapegroup and instance: a group's shapes appear only where an instance places them,
// each as the shape whose to_world is the instance's times its own (the same vertices and
// sphere as that plain shape, to the bit where the shape's own to_world is the identity); the
// group's materials are shared, its mesh read once. Errors as Mitsuba's: no emitter, group or
// instance in a group; an instance needs one ref to a group defined before it.
TEST(SceneLoader, ShapeGroupAndInstance) {
  Fixture f;
  Scene s;
  loadScene(f.scene(std::string(kSensor) + R"(
    <shape type="shapegroup" id="g">
      <shape type="ply"><string name="filename" value="tri.ply"/>
        <bsdf type="diffuse"><rgb name="reflectance" value="0.3"/></bsdf></shape>
      <shape type="sphere"><point name="center" x="1" y="0" z="0"/><float name="radius" value="0.5"/></shape>
    </shape>
    <shape type="instance"><ref id="g"/></shape>
    <shape type="instance"><ref id="g"/>
      <transform name="to_world"><rotate y="1" angle="90"/><scale value="2"/><translate x="5"/></transform></shape>
    <shape type="instance"><shape type="shapegroup"><shape type="rectangle"/></shape></shape>)"),
            {}, s);
  ASSERT_EQ(s.shapes.size(), 5u) << "two instances of two shapes, and one of an inline group's rectangle";
  EXPECT_TRUE(s.meshes.empty()) << "an instance's meshes are placements, not copies";
  ASSERT_EQ(s.prototypes.size(), 2u) << "the group's mesh once, however many instances place it, and the rectangle";
  ASSERT_EQ(s.instances.size(), 3u);
  ASSERT_EQ(s.spheres.size(), 2u);
  EXPECT_EQ(s.instances[0].prototype, s.instances[1].prototype);
  EXPECT_TRUE(s.shapes[0].isInstance && s.shapes[2].isInstance && s.shapes[4].isInstance);
  EXPECT_EQ(s.shapes[0].bsdf, s.shapes[2].bsdf) << "the group's material is shared";
  EXPECT_FLOAT_EQ(s.bsdfs[size_t(s.shapes[0].bsdf)].reflectance.x, 0.3f);
  EXPECT_EQ(s.triangleCount(), 1u + 1u + 2u) << "triangles as placed";
  EXPECT_EQ(s.view().meshCount, 3);
  // Geometry ids: the instanced meshes, then the spheres.
  EXPECT_EQ(s.geometryId(s.shapes[0]), 0u);
  EXPECT_EQ(s.geometryId(s.shapes[1]), 3u);
  EXPECT_EQ(s.geometryId(s.shapes[4]), 2u);
  // The plain shapes under the second instance's transform, as one scene would write them.
  Scene plain;
  loadScene(f.scene(std::string(kSensor) + R"(
    <shape type="ply"><string name="filename" value="tri.ply"/>
      <transform name="to_world"><rotate y="1" angle="90"/><scale value="2"/><translate x="5"/></transform></shape>
    <shape type="sphere"><point name="center" x="1" y="0" z="0"/><float name="radius" value="0.5"/>
      <transform name="to_world"><rotate y="1" angle="90"/><scale value="2"/><translate x="5"/></transform></shape>)"),
            {}, plain);
  const TriangleMesh& tri = s.prototypes[size_t(s.instances[0].prototype)];
  EXPECT_TRUE(sameVec(tri.positions[1], Vec3f(1.f, 0.f, 0.f))) << "the group's mesh in its own space";
  ASSERT_EQ(tri.positions.size(), 3u);
  const MeshView& placed = s.view().meshes[1];
  ASSERT_NE(placed.toWorld, nullptr);
  EXPECT_EQ(placed.positions, tri.positions.data()) << "the placement reads the group's arrays";
  for (int i = 0; i < 3; ++i) {
    Vec3f p = placed.toWorld->point(tri.positions[size_t(i)]), q = plain.meshes[0].positions[size_t(i)];
    EXPECT_LT(length(p - q), 1e-5f) << i;
    Vec3f n = normalize(placed.toWorld->normal(tri.normals[size_t(i)]));
    EXPECT_LT(length(n - plain.meshes[0].normals[size_t(i)]), 1e-6f) << i;
  }
  EXPECT_NEAR(placed.toWorld->point(tri.positions[1]).x, 5.f, 1e-6f);  // (1, 0, 0) turned to -z, doubled, moved by 5
  EXPECT_NEAR(placed.toWorld->point(tri.positions[1]).z, -2.f, 1e-6f);
  EXPECT_TRUE(sameVec(s.spheres[1].center, plain.spheres[0].center));
  EXPECT_FLOAT_EQ(s.spheres[1].radius, 1.f);
  EXPECT_TRUE(sameVec(s.spheres[0].center, Vec3f(1.f, 0.f, 0.f)));
  EXPECT_EQ(s.prototypes[size_t(s.instances[2].prototype)].positions.size(), 4u) << "the inline group's rectangle";
  // The scene's bounds take in each placement.
  EXPECT_NEAR(s.view().boundsMin.z, plain.view().boundsMin.z, 1e-5f);

  const std::pair<const char*, const char*> bad[] = {
      {R"(<shape type="shapegroup"><shape type="sphere"/></shape>)", "a shapegroup needs an id"},
      {R"(<shape type="shapegroup" id="g"><shape type="shapegroup" id="h"/></shape>)",
       "a shapegroup inside a shapegroup is not permitted"},
      {R"(<shape type="shapegroup" id="g"/><shape type="shapegroup" id="h"><shape type="instance"><ref id="g"/></shape></shape>)",
       "an instance inside a shapegroup is not permitted"},
      {R"(<shape type="shapegroup" id="g"><shape type="rectangle"><emitter type="area"/></shape></shape>)",
       "cannot be an area emitter"},
      {R"(<shape type="shapegroup" id="g"><bsdf type="diffuse"/></shape>)", "unexpected <bsdf> in a shapegroup"},
      {R"(<shape type="shapegroup" id="g"/><shape type="shapegroup" id="g"/>)", "duplicate id 'g'"},
      {R"(<shape type="instance"/>)", "an instance needs a <ref"},
      {R"(<shape type="instance"><ref id="nowhere"/></shape>)", "unknown shapegroup id 'nowhere'"},
      {R"(<bsdf type="diffuse" id="d"/><shape type="instance"><ref id="d"/></shape>)", "'d' is not a shapegroup"},
      {R"(<shape type="shapegroup" id="g"/><shape type="instance"><ref id="g"/><ref id="g"/></shape>)",
       "an instance refers to one shapegroup"},
      {R"(<shape type="shapegroup" id="g"/><shape type="instance"><ref id="g"/><bsdf type="diffuse"/></shape>)",
       "an instance refers to one shapegroup"},
      {R"(<shape type="instance"><bsdf type="diffuse"/></shape>)", "unexpected <bsdf> in an instance"},
      {R"(<shape type="shapegroup" id="g"/><shape type="instance"><ref id="g"/><float name="scale" value="2"/></shape>)",
       "shape 'instance' has no property 'scale'"},
      {R"(<shape type="shapegroup" id="g"><shape type="ply"/></shape>)", "ply shape needs a 'filename'"},
  };
  expectErrors(f, bad);
}

// Mitsuba's aov integrator: its list becomes the scene's AOVs and its one nested integrator the
// image's; a bad list, none or two nested integrators are errors at their lines.
TEST(SceneLoader, AovIntegrator) {
  Fixture f;
  Scene s;
  loadScene(f.scene(std::string(kSensor) + R"(
    <integrator type="aov"><string name="aovs" value="dd.y:depth,nn:sh_normal"/>
      <integrator type="path" name="my_image"><integer name="max_depth" value="3"/></integrator></integrator>)"),
            {}, s);
  ASSERT_EQ(s.aovs.size(), 2u);
  EXPECT_EQ(s.aovs[0].name, "dd.y");
  EXPECT_EQ(s.aovs[1].type, AovType::ShNormal);
  EXPECT_EQ(s.integrator.type, IntegratorType::Path);
  EXPECT_EQ(s.integrator.path.maxDepth, 3);
  const std::pair<const char*, const char*> bad[] = {
      {R"(<integrator type="aov"><string name="aovs" value="dd:depth"/></integrator>)",
       "an aov integrator needs a nested <integrator>"},
      {R"(<integrator type="aov"><string name="aovs" value="dd:depth"/><integrator type="path"/><integrator type="direct"/></integrator>)",
       "an aov integrator holds one integrator"},
      {R"(<integrator type="aov"><integrator type="aov"><integrator type="path"/></integrator></integrator>)",
       "an aov integrator inside an aov integrator"},
      {R"(<integrator type="aov"><string name="aovs" value="dd:dpth"/><integrator type="path"/></integrator>)",
       "unknown AOV type 'dpth'"},
      {R"(<integrator type="aov"><string name="aov" value="dd:depth"/><integrator type="path"/></integrator>)",
       "integrator 'aov' has no property 'aov' (did you mean 'aovs'?)"},
      {R"(<integrator type="aov"><string name="aovs" value="dd:depth"/><bsdf type="diffuse"/></integrator>)",
       "unexpected <bsdf> in <integrator>"},
  };
  expectErrors(f, bad);
}

// hdrfilm's pixel_format: rgba (and the other formats with alpha) asks for the film's A channel;
// the colour is written as RGB whatever the format, said once; an unknown format is an error.
TEST(SceneLoader, FilmPixelFormat) {
  Fixture f;
  for (const auto& [format, alpha] : std::vector<std::pair<std::string, bool>>{
           {"rgb", false}, {"rgba", true}, {"xyza", true}, {"luminance", false}, {"luminance_alpha", true}}) {
    Scene s;
    loadScene(sensorWithFilm(f, "<string name=\"pixel_format\" value=\"" + format + "\"/>", true), {}, s);
    EXPECT_EQ(s.filmAlpha, alpha) << format;
  }
  Scene s;
  loadScene(f.scene(std::string(kSensor)), {}, s);
  EXPECT_FALSE(s.filmAlpha) << "rgb unless the scene asks (Mitsuba's default is rgba)";
  EXPECT_NE(loadError(sensorWithFilm(f, "<string name=\"pixel_format\" value=\"rgbx\"/>", true))
                .find("unknown pixel_format 'rgbx'"),
            std::string::npos);
}

// An area emitter's radiance as a texture (nested or a <ref>): the shape keeps the texture and
// its mean (for the choice among lights); given with a radiance value too, or a <ref> to an
// unknown id, it is an error; a texture on another emitter's property is still only warned about.
TEST(SceneLoader, TexturedAreaEmitter) {
  Fixture f;
  Scene s;
  loadScene(f.scene(std::string(kSensor) + R"(
    <texture type="checkerboard" id="checks"><rgb name="color0" value="4"/><rgb name="color1" value="2"/></texture>
    <shape type="rectangle"><emitter type="area"><texture type="bitmap" name="radiance">
      <string name="filename" value="sky.exr"/></texture></emitter></shape>
    <shape type="sphere"><emitter type="area"><ref id="checks" name="radiance"/></emitter></shape>)"),
            {}, s);
  ASSERT_EQ(s.shapes.size(), 2u);
  EXPECT_TRUE(s.shapes[0].emissive);
  ASSERT_GE(s.shapes[0].radianceTexture, 0);
  EXPECT_FLOAT_EQ(s.shapes[0].radiance.x, 0.5f) << "the bitmap's mean";
  EXPECT_EQ(s.shapes[1].radianceTexture, 0) << "the named checkerboard";
  EXPECT_FLOAT_EQ(s.shapes[1].radiance.y, 3.f);
  EXPECT_EQ(s.view().lights[0].radianceTexture, s.shapes[0].radianceTexture);
  const std::pair<const char*, const char*> bad[] = {
      {R"(<shape type="sphere"><emitter type="area"><rgb name="radiance" value="2"/>
        <texture type="checkerboard" name="radiance"/></emitter></shape>)",
       "the area emitter's radiance is given twice"},
      {R"(<shape type="sphere"><emitter type="area"><texture type="checkerboard" name="radiance"/>
        <texture type="checkerboard" name="radiance"/></emitter></shape>)",
       "the area emitter's radiance is given twice"},
      {R"(<shape type="sphere"><emitter type="area"><ref id="nowhere" name="radiance"/></emitter></shape>)",
       "unknown texture id 'nowhere'"},
      {R"(<shape type="sphere"><emitter type="area"><bsdf type="diffuse"/></emitter></shape>)",
       "unexpected <bsdf> in <emitter>"},
  };
  expectErrors(f, bad);
}

// Mitsuba's serialized shape: shape_index picks the mesh, the file's face-normal flag means
// face_normals, to_world applies as to the other meshes; errors name the line.
TEST(SceneLoader, SerializedShape) {
  Fixture f;
  test::MeshData a, b;
  a.positions = {0, 0, 0, 1, 0, 0, 0, 1, 0};
  a.indices = {0, 1, 2};
  b = a;
  b.normals = {0, 0, 1, 0, 0, 1, 0, 0, 1};
  b.faceNormals = true;
  test::writeSerialized(f.dir, "m.serialized", {a, b});
  Scene s;
  loadScene(f.scene(std::string(kSensor) + R"(
    <shape type="serialized"><string name="filename" value="m.serialized"/></shape>
    <shape type="serialized"><string name="filename" value="m.serialized"/><integer name="shape_index" value="1"/>
      <transform name="to_world"><translate x="2"/></transform></shape>)"),
            {}, s);
  ASSERT_EQ(s.meshes.size(), 2u);
  EXPECT_EQ(s.meshes[0].normals.size(), 3u) << "computed, as for a PLY without normals";
  EXPECT_TRUE(s.meshes[1].normals.empty()) << "the file's face-normal flag";
  EXPECT_FLOAT_EQ(s.meshes[1].positions[1].x, 3.f);
  const std::pair<const char*, const char*> bad[] = {
      {R"(<shape type="serialized"><string name="filename" value="m.serialized"/><integer name="shape_index" value="2"/></shape>)",
       "shape_index 2 is out of range (the file holds 2 meshes)"},
      {R"(<shape type="serialized"><string name="filename" value="tri.ply"/></shape>)", "not a Mitsuba .serialized mesh"},
      {R"(<shape type="serialized"><string name="filename" value="none.serialized"/></shape>)", "does not exist"},
      {R"(<shape type="serialized"><string name="filename" value="m.serialized"/><integer name="shape_indx" value="1"/></shape>)",
       "shape 'serialized' has no property 'shape_indx' (did you mean 'shape_index'?)"},
  };
  expectErrors(f, bad);
}
