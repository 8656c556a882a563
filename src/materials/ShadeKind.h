// The kinds of material a hit is shaded as: each BSDF type, and blends apart (a blend mixes two
// materials of any types). Code that is handed only hits of one type may give the type as a
// constant (bsdfEvalPdfAs, bsdfSampleAs), and the compiler then keeps that type's code alone.
#pragma once

#include "materials/Bsdf.h"

namespace envgi {

// Principled is the last BsdfType.
constexpr int kBlendShadeKind = int(BsdfType::Principled) + 1;
constexpr int kShadeKinds = kBlendShadeKind + 1;

ENVGI_INLINE int shadeKindOf(const Bsdf& b) { return bsdfIsBlend(b) ? kBlendShadeKind : int(b.type); }

}  // namespace envgi
