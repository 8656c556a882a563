// A spatially varying colour read at a surface's (u, v): Mitsuba 3's `bitmap` and
// `checkerboard` textures as plain data, evaluated alike on host and device.
#pragma once

#include "core/Vec.h"

namespace envgi {

enum class TextureType : int { Bitmap = 0, Checkerboard };
enum class TextureWrap : int { Repeat = 0, Mirror, Clamp };

struct TextureView {
  TextureType type = TextureType::Bitmap;
  // to_uv as a 2D affine map: uv' = (m[0] u + m[1] v + m[2], m[3] u + m[4] v + m[5]).
  float toUv[6] = {1.f, 0.f, 0.f, 0.f, 1.f, 0.f};
  // Bitmap: linear RGB texels, row 0 at v = 0 (the image's top row, as in Mitsuba).
  const Color* texels = nullptr;
  int width = 0, height = 0;
  bool bilinear = true;
  TextureWrap wrap = TextureWrap::Repeat;
  // Checkerboard: color0 where floor(2u) and floor(2v) have the same parity, else color1.
  Color color0{0.4f}, color1{0.2f};
};

// A texel coordinate brought into [0, n) by the wrap mode (Mitsuba's semantics: mirror repeats
// the image flipped every other period).
ENVGI_INLINE int textureWrap(int i, int n, TextureWrap w) {
  if (w == TextureWrap::Clamp) return i < 0 ? 0 : (i >= n ? n - 1 : i);
  if (w == TextureWrap::Repeat) {
    int r = i % n;
    return r < 0 ? r + n : r;
  }
  int r = i % (2 * n);
  if (r < 0) r += 2 * n;
  return r < n ? r : 2 * n - 1 - r;
}

// Floor to int that keeps coordinates far outside the texture finite: beyond +-2^24 periods a
// float has no fraction left anyway, and NaN lands on texel 0.
ENVGI_INLINE int textureFloor(float x) {
  float f = floorf(x);
  if (!(f > -16777216.f)) return f != f ? 0 : -16777216;
  return f < 16777216.f ? int(f) : 16777216;
}

ENVGI_INLINE Color textureEval(const TextureView& t, Vec2f uvIn) {
  Vec2f uv(t.toUv[0] * uvIn.x + t.toUv[1] * uvIn.y + t.toUv[2], t.toUv[3] * uvIn.x + t.toUv[4] * uvIn.y + t.toUv[5]);
  if (t.type == TextureType::Checkerboard) {
    bool even = ((textureFloor(2.f * uv.x) + textureFloor(2.f * uv.y)) & 1) == 0;
    return even ? t.color0 : t.color1;
  }
  auto at = [&](int x, int y) {
    return t.texels[size_t(textureWrap(y, t.height, t.wrap)) * size_t(t.width) + size_t(textureWrap(x, t.width, t.wrap))];
  };
  float x = uv.x * float(t.width), y = uv.y * float(t.height);
  if (!t.bilinear) return at(textureFloor(x), textureFloor(y));
  // Texel centres sit at half-integer coordinates.
  x -= 0.5f;
  y -= 0.5f;
  int x0 = textureFloor(x), y0 = textureFloor(y);
  float fx = x - floorf(x), fy = y - floorf(y);
  if (!(fx >= 0.f && fx <= 1.f)) fx = 0.f;  // NaN or an infinite coordinate
  if (!(fy >= 0.f && fy <= 1.f)) fy = 0.f;
  return (at(x0, y0) * (1.f - fx) + at(x0 + 1, y0) * fx) * (1.f - fy) +
         (at(x0, y0 + 1) * (1.f - fx) + at(x0 + 1, y0 + 1) * fx) * fy;
}

// d/du and d/dv of the texture's luminance at uv (Mitsuba's eval_1_grad, which bumpmap reads):
// the bilinear interpolant's partials in texels, times the resolution, through to_uv's
// transpose. Piecewise-constant textures (checkerboard, nearest filtering) have none.
ENVGI_INLINE Vec2f textureLuminanceGradient(const TextureView& t, Vec2f uvIn) {
  if (t.type != TextureType::Bitmap || !t.bilinear) return Vec2f(0.f, 0.f);
  Vec2f uv(t.toUv[0] * uvIn.x + t.toUv[1] * uvIn.y + t.toUv[2], t.toUv[3] * uvIn.x + t.toUv[4] * uvIn.y + t.toUv[5]);
  auto at = [&](int x, int y) {
    return luminance(t.texels[size_t(textureWrap(y, t.height, t.wrap)) * size_t(t.width) + size_t(textureWrap(x, t.width, t.wrap))]);
  };
  float x = uv.x * float(t.width) - 0.5f, y = uv.y * float(t.height) - 0.5f;
  int x0 = textureFloor(x), y0 = textureFloor(y);
  float fx = x - floorf(x), fy = y - floorf(y);
  if (!(fx >= 0.f && fx <= 1.f)) fx = 0.f;
  if (!(fy >= 0.f && fy <= 1.f)) fy = 0.f;
  float f00 = at(x0, y0), f10 = at(x0 + 1, y0), f01 = at(x0, y0 + 1), f11 = at(x0 + 1, y0 + 1);
  float dx = ((1.f - fy) * (f10 - f00) + fy * (f11 - f01)) * float(t.width);
  float dy = ((1.f - fx) * (f01 - f00) + fx * (f11 - f10)) * float(t.height);
  return Vec2f(t.toUv[0] * dx + t.toUv[3] * dy, t.toUv[1] * dx + t.toUv[4] * dy);
}

}  // namespace envgi
