// Isotropic GGX (Trowbridge-Reitz) microfacet distribution with visible-normal sampling
// (Heitz 2018). Directions are in the local shading frame, z = normal.
#pragma once

#include "core/Vec.h"

namespace envgi {

struct GGX {
  float alpha;

  ENVGI_HD float D(Vec3f m) const {
    float cos2 = m.z * m.z;
    if (cos2 <= 0.f) return 0.f;
    float tan2 = (m.x * m.x + m.y * m.y) / cos2;
    float a2 = alpha * alpha;
    float e = 1.f + tan2 / a2;
    return 1.f / (kPi * a2 * cos2 * cos2 * e * e);
  }
  ENVGI_HD float lambda(Vec3f w) const {
    float cos2 = w.z * w.z;
    if (cos2 <= 0.f) return 0.f;
    float tan2 = (w.x * w.x + w.y * w.y) / cos2;
    return 0.5f * (std::sqrt(1.f + alpha * alpha * tan2) - 1.f);
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
    Vec3f wh = normalize(Vec3f(alpha * w.x, alpha * w.y, w.z));
    if (wh.z < 0.f) wh = -wh;
    Vec3f t1 = wh.z < 0.99999f ? normalize(cross(Vec3f(0.f, 0.f, 1.f), wh)) : Vec3f(1.f, 0.f, 0.f);
    Vec3f t2 = cross(wh, t1);
    // Uniform disk point, warped onto the visible half of the projected hemisphere.
    float r = std::sqrt(u.x), phi = 2.f * kPi * u.y;
    float px = r * std::cos(phi), py = r * std::sin(phi);
    float h = std::sqrt(fmaxf(0.f, 1.f - px * px));
    float s = 0.5f * (1.f + wh.z);
    py = (1.f - s) * h + s * py;
    float pz = safeSqrt(1.f - px * px - py * py);
    Vec3f nh = t1 * px + t2 * py + wh * pz;
    return normalize(Vec3f(alpha * nh.x, alpha * nh.y, fmaxf(1e-6f, nh.z)));
  }
};

}  // namespace envgi
