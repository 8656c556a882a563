// The rough dielectric coat of `roughplastic`, as Mitsuba 3 models it: light reaches the
// diffuse base through the coat with the rough interface's directional transmittance t(mu)
// (refraction through visible microfacets, masked on the way in), leaves it the same way,
// and the base's inter-reflection under the coat is 1 / (1 - Fdr_int) with Fdr_int the rough
// interface's hemispherical reflectance from inside. Both come from tables built once per
// (alpha, ior, distribution) on the host (RoughCoatTable.cpp); this header reads them on
// either device.
#pragma once

#include "core/Vec.h"

namespace envgi {

// Table layout, one node of kCoatStride floats per roughness: t(mu) at mu = i / 63 (Mitsuba's
// MI_ROUGH_TRANSMITTANCE_RES nodes, read by linear interpolation as Mitsuba reads them), then
// Fdr_int, then the hemispherical transmittance from outside 2 integral t(mu) mu dmu.
constexpr int kCoatRes = 64;
constexpr int kCoatStride = kCoatRes + 2;
// A textured alpha gets this many nodes, log-spaced over [kCoatAlphaMin, kCoatAlphaMax] (the
// range a textured roughness is clamped to), and reads between its two nearest.
constexpr int kCoatAlphaNodes = 32;
constexpr float kCoatAlphaMin = 1e-3f, kCoatAlphaMax = 4.f;

ENVGI_INLINE float coatNodeAlpha(int j, int nodes) {
  return kCoatAlphaMin * std::pow(kCoatAlphaMax / kCoatAlphaMin, float(j) / float(nodes - 1));
}

// The two nodes a roughness falls between and its weight towards the second.
struct CoatNode {
  const float* a;
  const float* b;
  float w;
};

ENVGI_INLINE CoatNode coatNode(const float* table, int nodes, float alpha) {
  if (nodes <= 1) return {table, table, 0.f};
  float x = std::log(alpha * (1.f / kCoatAlphaMin)) * (float(nodes - 1) / std::log(kCoatAlphaMax / kCoatAlphaMin));
  x = clampf(x, 0.f, float(nodes - 1));
  int j = x < float(nodes - 2) ? int(x) : nodes - 2;
  return {table + j * kCoatStride, table + (j + 1) * kCoatStride, x - float(j)};
}

ENVGI_INLINE float coatEntry(const CoatNode& n, int i) { return n.a[i] + n.w * (n.b[i] - n.a[i]); }

// Where mu = cos theta falls among t's nodes: the node i below it and the share t of the way on
// to i + 1. Apart from the lookup (coatTransmittanceAt) so that vector lanes can keep the node
// in an array between two loops: inside one, GCC turned the
// clamp's branches into a choice between addresses, which it does not gather from.
struct CoatPlace {
  int i;
  float t;
};
ENVGI_INLINE CoatPlace coatPlace(float mu) {
  float x = clampf(mu, 0.f, 1.f) * float(kCoatRes - 1);
  int i = x < float(kCoatRes - 2) ? int(x) : kCoatRes - 2;
  return {i, x - float(i)};
}
ENVGI_INLINE float coatTransmittanceAt(const CoatNode& n, CoatPlace p) {
  float v0 = coatEntry(n, p.i), v1 = coatEntry(n, p.i + 1);
  return v0 + p.t * (v1 - v0);
}
// t(mu): the share of light from a direction mu = cos theta above the coat that reaches the base.
ENVGI_INLINE float coatTransmittance(const CoatNode& n, float mu) { return coatTransmittanceAt(n, coatPlace(mu)); }
ENVGI_INLINE float coatInternalReflectance(const CoatNode& n) { return coatEntry(n, kCoatRes); }
ENVGI_INLINE float coatDiffuseTransmittance(const CoatNode& n) { return coatEntry(n, kCoatRes + 1); }

}  // namespace envgi
