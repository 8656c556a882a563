#include "materials/BsdfFactory.h"

#include <stdexcept>

namespace envgi {

void conductorPreset(const std::string& name, Color* eta, Color* k, bool* perfectMirror) {
  // RGB (sRGB primaries) projections of the measured spectra, as Mitsuba 3's scalar_rgb variant
  // computes them, so that envgi and Mitsuba render the same metals from the same XML (Cr was
  // 16% too dark before the cross-check compared them).
  struct Preset {
    const char* name;
    Color eta, k;
  };
  static const Preset presets[] = {
      {"Au", {0.143f, 0.374f, 1.442f}, {3.983f, 2.385f, 1.603f}},
      {"Ag", {0.155f, 0.117f, 0.138f}, {4.827f, 3.122f, 2.147f}},
      {"Cu", {0.200f, 0.924f, 1.102f}, {3.912f, 2.452f, 2.142f}},
      {"Al", {1.657f, 0.880f, 0.521f}, {9.224f, 6.270f, 4.837f}},
      {"Cr", {4.370f, 2.917f, 1.655f}, {5.207f, 4.231f, 3.755f}},
  };
  *perfectMirror = false;
  if (name == "none") {
    *perfectMirror = true;
    *eta = Color(0.f);
    *k = Color(1.f);
    return;
  }
  for (const Preset& p : presets)
    if (name == p.name) {
      *eta = p.eta;
      *k = p.k;
      return;
    }
  throw std::runtime_error("unknown conductor material '" + name + "' (none, Au, Ag, Cu, Al, Cr)");
}

float fresnelDiffuseReflectance(float eta) {
  const int n = 4096;  // midpoint rule; F is smooth except at the critical angle
  double sum = 0.0;
  for (int i = 0; i < n; ++i) {
    double mu = (i + 0.5) / n;
    sum += fresnelDielectric(float(mu), eta) * mu;
  }
  return float(2.0 * sum / n);
}

void finishPlastic(Bsdf& b) {
  b.fdrInt = fresnelDiffuseReflectance(1.f / b.ior);
  b.fdrExt = fresnelDiffuseReflectance(b.ior);
  float dMean = (b.reflectance.x + b.reflectance.y + b.reflectance.z) / 3.f;
  float sMean = (b.specularReflectance.x + b.specularReflectance.y + b.specularReflectance.z) / 3.f;
  b.specularSamplingWeight = sMean + dMean > 0.f ? sMean / (sMean + dMean) : 0.5f;
}

}  // namespace envgi
