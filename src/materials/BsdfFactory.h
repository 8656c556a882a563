// Host-side construction of BSDFs: named conductor presets and precomputed plastic terms.
#pragma once

#include <string>

#include "materials/Bsdf.h"

namespace envgi {

// RGB (eta, k) of a named conductor ("none" is a perfect mirror); throws for unknown names.
void conductorPreset(const std::string& name, Color* eta, Color* k, bool* perfectMirror);

// Hemispherical average of the dielectric Fresnel reflectance, 2 * integral F(mu) mu dmu.
float fresnelDiffuseReflectance(float eta);

// Fills the derived plastic terms (internal diffuse reflectance, sampling weight).
void finishPlastic(Bsdf& b);

}  // namespace envgi
