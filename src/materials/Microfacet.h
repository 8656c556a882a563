// Microfacet distributions, GGX (Trowbridge-Reitz) and Beckmann, as Mitsuba 3's
// `distribution` names them, isotropic or anisotropic (roughness alphaX along the frame's s,
// alphaY along t), with the Smith masking of each and visible-normal sampling (GGX: Heitz
// 2018; Beckmann: Heitz and d'Eon 2014, whose slope CDF is inverted numerically). Directions
// are in the local shading frame, z = normal.
#pragma once

#include <cstdint>

#include "core/ErfInv.h"
#include "core/Vec.h"
#include "sampling/Warp.h"

namespace envgi {

enum class MicrofacetType : uint8_t { GGX = 0, Beckmann = 1 };

struct MicrofacetDistribution {
  float alphaX, alphaY;
  MicrofacetType type = MicrofacetType::GGX;

  ENVGI_HD float D(Vec3f m) const {
    float cos2 = m.z * m.z;
    if (cos2 <= 0.f) return 0.f;
    // tan^2 of m over alpha^2 (over each axis' alpha^2 where they differ), and alphaX alphaY.
    float t, a2;
    if (alphaX == alphaY) {
      float tan2 = (m.x * m.x + m.y * m.y) / cos2;
      a2 = alphaX * alphaX;
      t = tan2 / a2;
    } else {
      t = (sqr(m.x / alphaX) + sqr(m.y / alphaY)) / cos2;
      a2 = alphaX * alphaY;
    }
    // Past t = 104, exp(-t) is 0 in float: said at once, not through libm's slow underflow path.
    if (type == MicrofacetType::Beckmann) return t > 104.f ? 0.f : std::exp(-t) / (kPi * a2 * cos2 * cos2);
    float e = 1.f + t;
    return 1.f / (kPi * a2 * cos2 * cos2 * e * e);
  }
  // Smith's lambda; G1 = 1 / (1 + lambda). Beckmann's is the exact form in erfc, which is what
  // makes its visible normals (sampleVisible) exactly the distribution visiblePdf states.
  ENVGI_HD float lambda(Vec3f w) const {
    float cos2 = w.z * w.z;
    if (cos2 <= 0.f) return 0.f;
    // alpha^2 tan^2 theta, with alpha the roughness along w's azimuth where the axes differ.
    float a2tan2;
    if (alphaX == alphaY) a2tan2 = alphaX * alphaX * ((w.x * w.x + w.y * w.y) / cos2);
    else a2tan2 = (sqr(alphaX * w.x) + sqr(alphaY * w.y)) / cos2;
    if (type == MicrofacetType::Beckmann) return beckmannLambda(a2tan2);
    return 0.5f * (std::sqrt(1.f + a2tan2) - 1.f);
  }
  ENVGI_HD float G1(Vec3f w) const { return 1.f / (1.f + lambda(w)); }
  // Height-correlated masking-shadowing.
  ENVGI_HD float G(Vec3f wo, Vec3f wi) const { return 1.f / (1.f + lambda(wo) + lambda(wi)); }

  // Density of visible normals seen from w: G1(w) max(0, w.m) D(m) / |cos w|.
  ENVGI_HD float visiblePdf(Vec3f w, Vec3f m) const {
    float c = std::fabs(w.z);
    if (c == 0.f) return 0.f;
    return G1(w) * std::fabs(dot(w, m)) * D(m) / c;
  }

  // Samples a visible normal for a view direction w (either hemisphere; flipped to +z).
  ENVGI_HD Vec3f sampleVisible(Vec3f w, Vec2f u) const {
    return type == MicrofacetType::Beckmann ? sampleVisibleBeckmann(w, u) : sampleVisibleGgx(w, u);
  }

 private:
  // Out of line on the device, as sampleVisibleBeckmann: erfc is long, and lambda is inlined
  // into every BSDF evaluation of every kernel.
  // Past a = 3.7, lambda is below 7e-9, which 1 + lambda (G1's and G's only use) rounds away
  // in float: 0 is returned without erfc and exp, whose underflow paths took a fifth of a
  // Beckmann-lit render, and G1 and G stay the same to the bit.
  ENVGI_HD_NOINLINE static float beckmannLambda(float a2tan2) {
    if (a2tan2 <= 1.f / (3.7f * 3.7f)) return 0.f;
    float a = 1.f / std::sqrt(a2tan2);  // 1 / (alpha tan theta)
    return fmaxf(0.f, 0.5f * (std::exp(-a * a) / (a * 1.7724538509f) - std::erfc(a)));
  }

  ENVGI_HD Vec3f sampleVisibleGgx(Vec3f w, Vec2f u) const { return visibleGgxFromDisk(w, fromPolar(visibleDiskPolar(u))); }

 public:
  // GGX's visible normal in two steps around libm (fromPolar): the uniform disk point that u
  // draws, in polar form, then the normal it is warped to, seen from w.
  ENVGI_HD static PolarPoint visibleDiskPolar(Vec2f u) { return {std::sqrt(u.x), 2.f * kPi * u.y}; }
  ENVGI_HD Vec3f visibleGgxFromDisk(Vec3f w, Vec2f disk) const {
    Vec3f wh = normalize(Vec3f(alphaX * w.x, alphaY * w.y, w.z));
    if (wh.z < 0.f) wh = -wh;
    Vec3f t1 = wh.z < 0.99999f ? normalize(cross(Vec3f(0.f, 0.f, 1.f), wh)) : Vec3f(1.f, 0.f, 0.f);
    Vec3f t2 = cross(wh, t1);
    // The disk point warped onto the visible half of the projected hemisphere.
    float px = disk.x, py = disk.y;
    // Maxima as comparisons, for the lanes: fmaxf does not vectorise, and these agree with it for
    // every value, NaN included (1 - px^2 is never -0).
    const float h2 = 1.f - px * px;
    float h = std::sqrt(h2 > 0.f ? h2 : 0.f);
    float s = 0.5f * (1.f + wh.z);
    py = (1.f - s) * h + s * py;
    float pz = safeSqrt(1.f - px * px - py * py);
    Vec3f nh = t1 * px + t2 * py + wh * pz;
    return normalize(Vec3f(alphaX * nh.x, alphaY * nh.y, nh.z > 1e-6f ? nh.z : 1e-6f));
  }

 private:
  // In the stretched frame (alpha = 1) and with w in the xz-plane at angle theta, the normal of
  // slope (x, y) is (-x, -y, 1) / |.|, seen with weight (1 - x tan theta) where x < cot theta,
  // and the slopes are Gaussian: y is a plain normal variate, x has the CDF
  //   C(x) = (1 + erf x + tan theta e^(-x^2) / sqrt(pi)) / (the same at x = cot theta),
  // solved for C(x) = u in b = erf x (bounded, monotone) by Newton steps kept in a bracket.
  ENVGI_HD static float visibleSlopeX(float tanTheta, float u) {
    if (tanTheta < 1e-5f) return erfInv(2.f * u - 1.f);
    float cot = 1.f / tanTheta;
    float k = tanTheta * 0.5641895835f;  // tan theta / sqrt(pi)
    float c = std::erf(cot);
    float norm = 1.f / (1.f + c + k * std::exp(-cot * cot));
    float lo = -1.f, hi = c;
    float b = -1.f + u * (1.f + c);  // exact at normal incidence
    for (int i = 0; i < 24; ++i) {
      if (!(b > lo && b < hi)) b = 0.5f * (lo + hi);
      float x = erfInv(b);
      float value = norm * (1.f + b + k * std::exp(-x * x)) - u;
      if (std::fabs(value) < 1e-6f) break;
      if (value > 0.f) hi = b;
      else lo = b;
      b -= value / (norm * (1.f - x * tanTheta));
    }
    return erfInv(b);
  }

  ENVGI_HD_NOINLINE Vec3f sampleVisibleBeckmann(Vec3f w, Vec2f u) const {
    if (w.z < 0.f) w = -w;
    Vec3f wh = normalize(Vec3f(alphaX * w.x, alphaY * w.y, fmaxf(w.z, 1e-7f)));
    float sinTheta = std::sqrt(wh.x * wh.x + wh.y * wh.y);
    float cosPhi = 1.f, sinPhi = 0.f;
    if (sinTheta > 0.f) {
      cosPhi = wh.x / sinTheta;
      sinPhi = wh.y / sinTheta;
    }
    float ux = clampf(u.x, 1e-6f, 1.f - 1e-6f), uy = clampf(u.y, 1e-6f, 1.f - 1e-6f);
    float sx = visibleSlopeX(sinTheta / wh.z, ux);
    float sy = erfInv(2.f * uy - 1.f);
    // Back to w's azimuth, then unstretched.
    float x = alphaX * (cosPhi * sx - sinPhi * sy), y = alphaY * (sinPhi * sx + cosPhi * sy);
    return normalize(Vec3f(-x, -y, 1.f));
  }
};

}  // namespace envgi
