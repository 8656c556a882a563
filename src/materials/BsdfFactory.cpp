#include "materials/BsdfFactory.h"

#include <stdexcept>
#include <string>

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
      {"a-C", {2.944f, 2.227f, 1.968f}, {0.887f, 0.799f, 0.815f}},
      {"AlAs", {3.605f, 3.233f, 2.216f}, {0.001f, 0.000f, 0.008f}},
      {"AlSb", {0.000f, 4.139f, 4.669f}, {0.000f, 0.094f, 1.301f}},
      {"Be", {4.185f, 3.185f, 2.784f}, {3.835f, 3.010f, 2.869f}},
      {"CsI", {2.145f, 1.702f, 1.662f}, {0.000f, 0.000f, 0.000f}},
      {"Cu_palik", {0.213f, 0.920f, 1.102f}, {3.922f, 2.457f, 2.137f}},
      {"Cu2O", {3.552f, 2.950f, 2.752f}, {0.114f, 0.194f, 0.606f}},
      {"CuO", {3.248f, 2.448f, 2.210f}, {0.521f, 0.570f, 0.722f}},
      {"d-C", {2.709f, 2.319f, 2.229f}, {0.000f, 0.000f, 0.000f}},
      {"Hg", {2.399f, 1.440f, 0.910f}, {6.328f, 4.372f, 3.422f}},
      {"HgTe", {4.779f, 3.231f, 2.660f}, {1.632f, 1.581f, 1.729f}},
      {"Ir", {3.086f, 2.082f, 1.618f}, {5.592f, 4.067f, 3.267f}},
      {"K", {0.064f, 0.046f, 0.038f}, {2.104f, 1.349f, 0.913f}},
      {"Li", {0.266f, 0.196f, 0.221f}, {3.540f, 2.311f, 1.669f}},
      {"MgO", {2.090f, 1.651f, 1.595f}, {0.000f, 0.000f, 0.000f}},
      {"Mo", {4.484f, 3.525f, 2.776f}, {4.111f, 3.421f, 3.151f}},
      {"Na_palik", {0.060f, 0.056f, 0.062f}, {3.179f, 2.112f, 1.579f}},
      {"Nb", {3.420f, 2.790f, 2.396f}, {3.441f, 2.738f, 2.580f}},
      {"Ni_palik", {2.367f, 1.663f, 1.467f}, {4.499f, 3.050f, 2.345f}},
      {"Rh", {2.586f, 1.860f, 1.554f}, {6.782f, 4.703f, 3.976f}},
      {"Se", {4.058f, 2.843f, 2.821f}, {0.754f, 0.638f, 0.522f}},
      {"SiC", {3.172f, 2.526f, 2.479f}, {0.000f, 0.000f, 0.000f}},
      {"SnTe", {4.524f, 1.982f, 1.282f}, {0.000f, 0.000f, 0.000f}},
      {"Ta", {2.063f, 2.393f, 2.628f}, {2.408f, 1.741f, 1.947f}},
      {"Te", {7.390f, 4.482f, 2.637f}, {3.256f, 3.527f, 3.292f}},
      {"ThF4", {1.831f, 1.442f, 1.388f}, {0.000f, 0.000f, 0.000f}},
      {"TiC", {3.701f, 2.837f, 2.582f}, {3.266f, 2.352f, 2.173f}},
      {"TiN", {1.648f, 1.151f, 1.380f}, {3.368f, 1.943f, 1.102f}},
      {"TiO2", {3.457f, 2.802f, 2.905f}, {0.000f, 0.000f, 0.001f}},
      {"VC", {3.658f, 2.753f, 2.533f}, {3.068f, 2.199f, 1.963f}},
      {"V_palik", {4.278f, 3.513f, 2.761f}, {3.491f, 2.889f, 3.112f}},
      {"VN", {2.866f, 2.119f, 1.940f}, {3.032f, 2.056f, 1.616f}},
      {"W", {4.371f, 3.300f, 2.998f}, {3.501f, 2.605f, 2.273f}},
  };
  // Mitsuba also reads these with "_palik" after them (the same data; Cu_palik is its own above).
  static const char* const palikAliases[] = {"AlAs", "AlSb", "Be",   "CsI", "Cu2O", "CuO", "d-C",  "Hg", "HgTe", "Ir",
                                             "K",    "Li",   "MgO",  "Mo",  "Nb",   "Rh",  "Se",   "SiC", "SnTe", "Ta",
                                             "Te",   "ThF4", "TiC",  "TiN", "TiO2", "VC",  "VN"};
  std::string key = name;
  for (const char* a : palikAliases)
    if (name == std::string(a) + "_palik") key = a;
  *perfectMirror = false;
  if (name == "none") {
    *perfectMirror = true;
    *eta = Color(0.f);
    *k = Color(1.f);
    return;
  }
  std::string known = "none";
  for (const Preset& p : presets) {
    if (key == p.name) {
      *eta = p.eta;
      *k = p.k;
      return;
    }
    known += std::string(", ") + p.name;
  }
  throw std::runtime_error("unknown conductor material '" + name + "' (" + known + ", and most with _palik)");
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
