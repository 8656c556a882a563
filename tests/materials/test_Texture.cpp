// Texture lookups against their definitions: texel centres, bilinear weights, each wrap mode,
// to_uv, the checkerboard's parity, and coordinates no texture should crash on.
#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "materials/Texture.h"

using namespace envgi;

namespace {

// A 4x2 texture whose texel (x, y) has red x and green y: any lookup says where it landed.
struct Ramp {
  std::vector<Color> texels;
  TextureView view;
  explicit Ramp(TextureWrap wrap = TextureWrap::Repeat, bool bilinear = true) {
    for (int y = 0; y < 2; ++y)
      for (int x = 0; x < 4; ++x) texels.push_back(Color(float(x), float(y), 1.f));
    view.texels = texels.data();
    view.width = 4;
    view.height = 2;
    view.wrap = wrap;
    view.bilinear = bilinear;
  }
};

void expectColor(Color got, Color want, const char* what) {
  EXPECT_NEAR(got.x, want.x, 1e-5f) << what;
  EXPECT_NEAR(got.y, want.y, 1e-5f) << what;
  EXPECT_NEAR(got.z, want.z, 1e-5f) << what;
}

}  // namespace

TEST(Texture, WrapModesFoldIndicesAsMitsubaDoes) {
  const int n = 4;
  int repeat[] = {2, 3, 0, 1, 2, 3, 0, 1, 2, 3};  // i = -2 .. 7
  int mirror[] = {1, 0, 0, 1, 2, 3, 3, 2, 1, 0};
  int clamp[] = {0, 0, 0, 1, 2, 3, 3, 3, 3, 3};
  for (int i = -2; i <= 7; ++i) {
    EXPECT_EQ(textureWrap(i, n, TextureWrap::Repeat), repeat[i + 2]) << i;
    EXPECT_EQ(textureWrap(i, n, TextureWrap::Mirror), mirror[i + 2]) << i;
    EXPECT_EQ(textureWrap(i, n, TextureWrap::Clamp), clamp[i + 2]) << i;
  }
  EXPECT_EQ(textureWrap(-10, 4, TextureWrap::Mirror), 1);  // -10 mod 8 = 6, mirrored to 1
}

TEST(Texture, BilinearHitsTexelCentresAndBlendsBetweenThem) {
  Ramp r;
  // Texel (x, y) has its centre at ((x + 0.5) / 4, (y + 0.5) / 2); row 0 is v = 0.
  expectColor(textureEval(r.view, Vec2f(0.125f, 0.25f)), Color(0.f, 0.f, 1.f), "texel (0,0)");
  expectColor(textureEval(r.view, Vec2f(0.625f, 0.75f)), Color(2.f, 1.f, 1.f), "texel (2,1)");
  // Halfway between texels 1 and 2, a quarter of the way from row 0 to row 1.
  expectColor(textureEval(r.view, Vec2f(0.5f, 0.375f)), Color(1.5f, 0.25f, 1.f), "between");
  // Repeat: left of texel 0's centre blends with texel 3.
  expectColor(textureEval(r.view, Vec2f(0.f, 0.25f)), Color(1.5f, 0.f, 1.f), "u = 0 wraps");
  Ramp c(TextureWrap::Clamp);
  expectColor(textureEval(c.view, Vec2f(0.f, 0.25f)), Color(0.f, 0.f, 1.f), "u = 0 clamps");
  expectColor(textureEval(c.view, Vec2f(7.f, -3.f)), Color(3.f, 0.f, 1.f), "far outside clamps");
}

TEST(Texture, NearestTakesTheTexelUnderTheCoordinate) {
  Ramp r(TextureWrap::Repeat, false);
  expectColor(textureEval(r.view, Vec2f(0.49f, 0.51f)), Color(1.f, 1.f, 1.f), "nearest");
  expectColor(textureEval(r.view, Vec2f(1.3f, -0.2f)), Color(1.f, 1.f, 1.f), "nearest, repeated");
  Ramp m(TextureWrap::Mirror, false);
  expectColor(textureEval(m.view, Vec2f(1.1f, 0.2f)), Color(3.f, 0.f, 1.f), "nearest, mirrored");
}

TEST(Texture, ToUvTransformsBeforeTheLookup) {
  Ramp r(TextureWrap::Repeat, false);
  // uv' = (2u + 0.25, v): u = 0.1 lands at 0.45, texel 1.
  float m[6] = {2.f, 0.f, 0.25f, 0.f, 1.f, 0.f};
  std::copy(m, m + 6, r.view.toUv);
  expectColor(textureEval(r.view, Vec2f(0.1f, 0.1f)), Color(1.f, 0.f, 1.f), "scaled and shifted");
  // A quarter turn: uv' = (-v, u).
  float q[6] = {0.f, -1.f, 0.f, 1.f, 0.f, 0.f};
  std::copy(q, q + 6, r.view.toUv);
  expectColor(textureEval(r.view, Vec2f(0.7f, 0.3f)), Color(2.f, 1.f, 1.f), "rotated");  // (-0.3, 0.7) -> (0.7, 0.7)
}

TEST(Texture, CheckerboardAlternatesEveryHalfPeriod) {
  TextureView t;
  t.type = TextureType::Checkerboard;
  t.color0 = Color(1.f, 0.f, 0.f);
  t.color1 = Color(0.f, 0.f, 1.f);
  struct Case {
    float u, v;
    bool first;
  } cases[] = {{0.1f, 0.1f, true},  {0.6f, 0.1f, false}, {0.1f, 0.6f, false}, {0.6f, 0.6f, true},
               {1.1f, 0.1f, true},  {-0.1f, 0.1f, false}, {-0.6f, -0.6f, true}, {2.7f, -3.2f, true}};
  for (const Case& c : cases)
    expectColor(textureEval(t, Vec2f(c.u, c.v)), c.first ? t.color0 : t.color1, "checker");
  // Mitsuba's defaults.
  TextureView d;
  EXPECT_EQ(d.color0.x, 0.4f);
  EXPECT_EQ(d.color1.x, 0.2f);
}

// NaN, infinite and huge coordinates still read a texel of the texture, never outside it.
TEST(Texture, AnyCoordinateReadsInsideTheTexture) {
  const float bad[] = {NAN, INFINITY, -INFINITY, 1e30f, -1e30f, 3e9f, -3e9f};
  for (TextureWrap w : {TextureWrap::Repeat, TextureWrap::Mirror, TextureWrap::Clamp})
    for (bool bilinear : {true, false}) {
      Ramp r(w, bilinear);
      for (float a : bad)
        for (float b : {0.3f, a}) {
          Color c = textureEval(r.view, Vec2f(a, b));
          EXPECT_TRUE(c.x >= 0.f && c.x <= 3.f && c.y >= 0.f && c.y <= 1.f && c.z == 1.f)
              << a << ", " << b << " wrap " << int(w) << " bilinear " << bilinear;
        }
    }
}

// Bump maps read the luminance's gradient (Mitsuba's eval_1_grad): against central differences
// of the lookup itself, inside texels, through a to_uv that scales, turns and shifts, and with
// a wrap; piecewise-constant textures have none.
TEST(Texture, LuminanceGradientIsTheLookupsDerivative) {
  std::vector<Color> texels;
  for (int i = 0; i < 15; ++i) texels.push_back(Color(0.1f * float(i % 4), 0.05f * float(i * i % 7), 0.3f * float(i % 3)));
  TextureView t;
  t.texels = texels.data();
  t.width = 5;
  t.height = 3;
  float m[6] = {0.8f, -1.3f, 0.2f, 1.1f, 0.6f, -0.4f};
  std::copy(m, m + 6, t.toUv);
  const float h = 1e-3f;
  auto lum = [&](Vec2f uv) { return double(luminance(textureEval(t, uv))); };
  int checked = 0;
  for (Vec2f uv : {Vec2f(0.13f, 0.27f), Vec2f(0.61f, 0.42f), Vec2f(0.92f, 0.77f), Vec2f(-0.35f, 1.8f)}) {
    Vec2f g = textureLuminanceGradient(t, uv);
    double du = (lum(Vec2f(uv.x + h, uv.y)) - lum(Vec2f(uv.x - h, uv.y))) / (2 * h);
    double dv = (lum(Vec2f(uv.x, uv.y + h)) - lum(Vec2f(uv.x, uv.y - h))) / (2 * h);
    EXPECT_NEAR(g.x, du, 2e-2 * (1.0 + std::fabs(du))) << uv.x << "," << uv.y;
    EXPECT_NEAR(g.y, dv, 2e-2 * (1.0 + std::fabs(dv))) << uv.x << "," << uv.y;
    checked += std::fabs(du) + std::fabs(dv) > 0.1;
  }
  EXPECT_GE(checked, 3) << "the texture varies where it is probed";
  t.bilinear = false;
  EXPECT_EQ(textureLuminanceGradient(t, Vec2f(0.13f, 0.27f)).x, 0.f);
  t.type = TextureType::Checkerboard;
  EXPECT_EQ(textureLuminanceGradient(t, Vec2f(0.13f, 0.27f)).y, 0.f);
}
