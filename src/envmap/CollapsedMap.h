// The collapsed map (the paper's Section 2, "simplified representation ... using weighted
// sampling"): the environment turned into N directional lights shared by every shading point.
// Biased by construction: fast, noise-free in the light's direction, wrong in its shape.
#pragma once

#include <vector>

#include "envmap/EnvironmentMap.h"

namespace envgi {

enum class CollapseMethod { WeightedSampling, MedianCut };

// The most lights a collapsed map may have (600 MB of them): far past any count that still
// makes it fast, and a bound that turns a slip (point_count 2000000000) into an error line
// rather than an allocation the machine refuses.
inline constexpr int kMaxCollapsedPoints = 1 << 24;

// N directions drawn by Algorithm 1's density as the bilinear lookup matches it
// (importance-bilinear: L / pdf is flatter than under the per-pixel table, so N lights carry the
// map's power closer), stratified, Owen-scrambled Sobol' points for `seed`, each with
// irradiance L / (pdf N): their sum estimates the map's integral.
std::vector<DirectionalLight> collapseByWeightedSampling(const EnvironmentMap& map, int n, uint32_t seed);

// Debevec's median cut (2005): the map split into N regions of equal luminance power (always
// across the region's longer side in angle), each a light at its power centroid carrying the
// region's integral of L. The sum over lights is the map's integral.
std::vector<DirectionalLight> collapseByMedianCut(const EnvironmentMap& map, int n);

}  // namespace envgi
