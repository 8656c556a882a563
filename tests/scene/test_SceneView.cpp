// The shading frames SceneView::interaction builds: for anisotropic materials its s follows
// dp/du as Mitsuba's does (the mesh's (u, v), the barycentric ones without them, a sphere's
// azimuth), so alpha_u and alpha_v land on the directions a Mitsuba scene means.
#include <gtest/gtest.h>

#include "scene/Scene.h"

using namespace envgi;

namespace {

void expectNear(Vec3f a, Vec3f b, const char* what) {
  EXPECT_NEAR(a.x, b.x, 1e-5f) << what;
  EXPECT_NEAR(a.y, b.y, 1e-5f) << what;
  EXPECT_NEAR(a.z, b.z, 1e-5f) << what;
}

// The tangent dpdu made orthogonal to n, normalised.
Vec3f tangentAlong(Vec3f n, Vec3f dpdu) { return normalize(dpdu - n * dot(n, dpdu)); }

}  // namespace

TEST(SceneView, AnisotropicFramesFollowDpDu) {
  Scene s;
  Bsdf iso;
  iso.type = BsdfType::RoughConductor;
  Bsdf aniso = iso;
  aniso.alphaV = 0.4f;
  s.bsdfs = {iso, aniso};
  // A tilted triangle whose u runs from vertex 0 to vertex 2 (so dp/du = p2 - p0), with smooth
  // normals that lean away from the face's, and a copy without (u, v) or normals.
  TriangleMesh m;
  m.positions = {Vec3f(0.f, 0.f, 0.f), Vec3f(2.f, 0.f, 0.5f), Vec3f(0.f, 3.f, 1.f)};
  m.uvs = {Vec2f(0.f, 0.f), Vec2f(0.f, 1.f), Vec2f(1.f, 0.f)};
  Vec3f lean = normalize(Vec3f(0.2f, -0.1f, 1.f));
  m.normals = {lean, lean, lean};
  m.indices = {0, 1, 2};
  TriangleMesh bare = m;
  bare.uvs.clear();
  bare.normals.clear();
  s.meshes = {m, m, bare};
  Sphere sp;
  sp.center = Vec3f(0.f, 0.f, 5.f);
  sp.radius = 2.f;
  sp.axes = Frame::fromNormal(normalize(Vec3f(0.3f, 0.4f, 1.f)));  // a turned sphere
  s.spheres = {sp, sp};
  s.shapes = {{false, 0, 0, false, Color(0.f)}, {false, 1, 1, false, Color(0.f)}, {false, 2, 1, false, Color(0.f)},
              {true, 0, 0, false, Color(0.f)},  {true, 1, 1, false, Color(0.f)}};
  s.finalize();
  const SceneView& v = s.view();

  Hit h;
  h.primId = 0;
  h.u = 0.3f;
  h.v = 0.2f;
  h.t = 1.f;
  Ray r{Vec3f(0.f, 0.f, 10.f), Vec3f(0.f, 0.f, -1.f), 100.f};
  h.geomId = 0;
  SurfaceInteraction isoSi = v.interaction(r, h);
  h.geomId = 1;
  SurfaceInteraction anSi = v.interaction(r, h);
  expectNear(isoSi.shading.n, lean, "isotropic: the smooth normal");
  expectNear(isoSi.shading.s, Frame::fromNormal(lean).s, "isotropic: the frame is fromNormal's");
  expectNear(anSi.shading.n, lean, "anisotropic: the same normal");
  expectNear(anSi.shading.s, tangentAlong(lean, m.positions[2] - m.positions[0]), "mesh: s along dp/du");
  expectNear(anSi.shading.t, cross(lean, anSi.shading.s), "t = n x s");
  h.geomId = 2;  // no (u, v): Mitsuba's barycentric ones, dp/du = p1 - p0
  SurfaceInteraction bareSi = v.interaction(r, h);
  expectNear(bareSi.shading.s, tangentAlong(bareSi.shading.n, m.positions[1] - m.positions[0]), "bare mesh");

  // Spheres: s along increasing azimuth about the sphere's own z, (-y, x, 0) in its frame.
  Vec3f dir = normalize(Vec3f(0.5f, -0.3f, -1.f));
  Ray rs{Vec3f(0.f, 0.f, 5.f) - dir * 10.f, dir, 100.f};
  Hit hs;
  hs.primId = 0;
  hs.t = 8.f;  // the near hit: 10 - 2
  for (int k = 0; k < 2; ++k) {
    hs.geomId = int(s.meshes.size()) + k;
    SurfaceInteraction si = v.interaction(rs, hs);
    Vec3f n = si.shading.n, l = sp.axes.toLocal(n);
    if (k == 0) expectNear(si.shading.s, Frame::fromNormal(n).s, "isotropic sphere");
    else expectNear(si.shading.s, tangentAlong(n, sp.axes.toWorld(Vec3f(-l.y, l.x, 0.f))), "sphere: s along azimuth");
    EXPECT_NEAR(dot(si.shading.s, n), 0.f, 1e-6f);
  }
}

// A bump-mapped material: interaction() gives dp/du and dp/dv in the shading frame (a square
// of side 3 whose (u, v) run along x and y; a sphere's Mitsuba coordinates, 2 pi r sin theta
// along s and pi r against t), and bsdfAt turns a height rising linearly along u into the
// normal of the surface it displaces to, (-dh/du, 0, 3) normalised.
TEST(SceneView, BumpMapTiltsTheNormalByTheHeightsGradient) {
  Scene s;
  Texture ramp;  // luminance 0.1 x in texel x: dh/du = 0.1 * width within the interior
  ramp.params.width = 8;
  ramp.params.height = 2;
  ramp.params.wrap = TextureWrap::Clamp;
  for (int y = 0; y < 2; ++y)
    for (int x = 0; x < 8; ++x) ramp.texels.push_back(Color(0.1f * float(x)));
  s.textures = {ramp};
  Bsdf bumped;
  bumped.bumpTexture = 0;
  bumped.bumpScale = 2.f;
  s.bsdfs = {bumped};
  TriangleMesh m;
  m.positions = {Vec3f(0.f, 0.f, 0.f), Vec3f(3.f, 0.f, 0.f), Vec3f(0.f, 3.f, 0.f)};
  m.uvs = {Vec2f(0.f, 0.f), Vec2f(1.f, 0.f), Vec2f(0.f, 1.f)};
  m.indices = {0, 1, 2};
  s.meshes = {m};
  Sphere sp;
  sp.radius = 2.f;
  s.spheres = {sp};
  s.shapes = {{false, 0, 0, false, Color(0.f)}, {true, 0, 0, false, Color(0.f)}};
  s.finalize();
  const SceneView& v = s.view();

  Hit h;
  h.geomId = 0;
  h.primId = 0;
  h.u = 0.4f;  // u = 0.4: between texel centres 2.5 and 3.5
  h.v = 0.2f;
  h.t = 1.f;
  SurfaceInteraction si = v.interaction(Ray{Vec3f(1.2f, 0.6f, 1.f), Vec3f(0.f, 0.f, -1.f), 10.f}, h);
  EXPECT_NEAR(si.dpdu.x, 3.f, 1e-5f);
  EXPECT_NEAR(si.dpdu.y, 0.f, 1e-5f);
  EXPECT_NEAR(si.dpdv.x, 0.f, 1e-5f);
  EXPECT_NEAR(si.dpdv.y, 3.f, 1e-5f);  // t = n x s = y
  BsdfScratch scratch;
  const Bsdf& b = v.bsdfAt(si, &scratch);
  Vec3f want = normalize(Vec3f(-2.f * 0.1f * 8.f, 0.f, 3.f));
  Vec3f got = si.shading.toWorld(b.mappedNormal);
  expectNear(got, want, "bumped mesh normal, world");
  EXPECT_TRUE(bsdfIsNormalMapped(b));

  Vec3f dir = normalize(Vec3f(0.3f, -0.2f, -1.f));
  Ray rs{-dir * 10.f, dir, 100.f};
  Hit hs;
  hs.geomId = 1;
  hs.primId = 0;
  hs.t = 8.f;
  SurfaceInteraction ss = v.interaction(rs, hs);
  Vec3f n = ss.shading.n;
  float sinTheta = std::sqrt(n.x * n.x + n.y * n.y);
  EXPECT_NEAR(ss.dpdu.x, 2.f * kPi * 2.f * sinTheta, 1e-4f);
  EXPECT_NEAR(ss.dpdu.y, 0.f, 1e-4f);
  EXPECT_NEAR(ss.dpdv.x, 0.f, 1e-4f);
  EXPECT_NEAR(ss.dpdv.y, -kPi * 2.f, 1e-4f);
}
