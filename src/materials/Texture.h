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

// to_uv applied: where in the texture a surface's (u, v) reads.
ENVGI_INLINE Vec2f textureCoords(const TextureView& t, Vec2f uv) {
  return Vec2f(t.toUv[0] * uv.x + t.toUv[1] * uv.y + t.toUv[2], t.toUv[3] * uv.x + t.toUv[4] * uv.y + t.toUv[5]);
}

// A bitmap's texel (x, y), wrapped into the image.
ENVGI_INLINE const Color& textureTexel(const TextureView& t, int x, int y) {
  return t.texels[size_t(textureWrap(y, t.height, t.wrap)) * size_t(t.width) + size_t(textureWrap(x, t.width, t.wrap))];
}

// The four texels a bilinear lookup at texture coordinates uv blends: the lower corner and the
// weights of the upper ones. Texel centres sit at half-integer coordinates.
struct BilinearCell {
  int x0, y0;
  float fx, fy;
};
ENVGI_INLINE BilinearCell textureBilinearCell(const TextureView& t, Vec2f uv) {
  float x = uv.x * float(t.width) - 0.5f, y = uv.y * float(t.height) - 0.5f;
  BilinearCell c{textureFloor(x), textureFloor(y), x - floorf(x), y - floorf(y)};
  if (!(c.fx >= 0.f && c.fx <= 1.f)) c.fx = 0.f;  // NaN or an infinite coordinate
  if (!(c.fy >= 0.f && c.fy <= 1.f)) c.fy = 0.f;
  return c;
}

ENVGI_INLINE Color textureEval(const TextureView& t, Vec2f uvIn) {
  Vec2f uv = textureCoords(t, uvIn);
  if (t.type == TextureType::Checkerboard) {
    bool even = ((textureFloor(2.f * uv.x) + textureFloor(2.f * uv.y)) & 1) == 0;
    return even ? t.color0 : t.color1;
  }
  if (!t.bilinear) return textureTexel(t, textureFloor(uv.x * float(t.width)), textureFloor(uv.y * float(t.height)));
  BilinearCell c = textureBilinearCell(t, uv);
  auto at = [&](int dx, int dy) { return textureTexel(t, c.x0 + dx, c.y0 + dy); };
  return (at(0, 0) * (1.f - c.fx) + at(1, 0) * c.fx) * (1.f - c.fy) + (at(0, 1) * (1.f - c.fx) + at(1, 1) * c.fx) * c.fy;
}

// d/du and d/dv of the texture's luminance at uv (Mitsuba's eval_1_grad, which bumpmap reads):
// the bilinear interpolant's partials in texels, times the resolution, through to_uv's
// transpose. Piecewise-constant textures (checkerboard, nearest filtering) have none.
ENVGI_INLINE Vec2f textureLuminanceGradient(const TextureView& t, Vec2f uvIn) {
  if (t.type != TextureType::Bitmap || !t.bilinear) return Vec2f(0.f, 0.f);
  BilinearCell c = textureBilinearCell(t, textureCoords(t, uvIn));
  auto at = [&](int dx, int dy) { return luminance(textureTexel(t, c.x0 + dx, c.y0 + dy)); };
  float f00 = at(0, 0), f10 = at(1, 0), f01 = at(0, 1), f11 = at(1, 1);
  float dx = ((1.f - c.fy) * (f10 - f00) + c.fy * (f11 - f01)) * float(t.width);
  float dy = ((1.f - c.fx) * (f01 - f00) + c.fx * (f11 - f10)) * float(t.height);
  return Vec2f(t.toUv[0] * dx + t.toUv[3] * dy, t.toUv[1] * dx + t.toUv[4] * dy);
}

}  // namespace envgi
