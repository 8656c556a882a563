// Host-side construction of BSDFs: named conductor presets and precomputed plastic terms.
#pragma once

#include <string>

#include "materials/Bsdf.h"

namespace envgi {

// RGB (eta, k) of a named conductor ("none" is a perfect mirror); throws for unknown names.
void conductorPreset(const std::string& name, Color* eta, Color* k, bool* perfectMirror);

// Hemispherical average of the dielectric Fresnel reflectance, 2 * integral F(mu) mu dmu.
float fresnelDiffuseReflectance(float eta);

// Fills the derived plastic terms (internal diffuse reflectance, sampling weight). A rough
// plastic's coat tables depend on its alpha texture, known only later: Scene::finalize (or
// attachRoughCoat) attaches them.
void finishPlastic(Bsdf& b);

// The tables of a rough plastic's coat (materials/RoughCoat.h) at roughness alpha, or over all
// roughnesses where alpha is textured (*nodes says how many); built on first use and kept, so
// the pointer stays valid for the life of the process.
const float* roughCoatTable(float alpha, float ior, MicrofacetType type, bool texturedAlpha, int* nodes);

// Points a rough plastic at its coat's tables for its alpha, ior, distribution and whether its
// alpha is textured; call again after changing any of them. Leaves other BSDFs alone.
void attachRoughCoat(Bsdf& b);

}  // namespace envgi
