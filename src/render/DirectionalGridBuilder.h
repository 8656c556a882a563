// The paper's grid (basis = directions) before its fill: the M directions with their shares of
// the sphere, and the grid over the scene's bounds that holds M coefficients a point.
#pragma once

#include <algorithm>
#include <vector>

#include "photon/DirectionalGrid.h"
#include "render/IlluminationGridBuilder.h"

namespace envgi {

// The M directions and their shares of the sphere (ΔΦ_p): half drawn from the collapsed map
// (Algorithm 1's density) where the scene has a map, the rest a spiral even over the sphere;
// each share is 1 / (M p_mix), p_mix the two densities mixed by their counts (Eq. 5-6).
void gridDirections(const Scene& scene, int m, uint32_t seed, std::vector<Vec3f>* dirs, std::vector<float>* share);

// A directional grid over the scene's bounds, as makeIlluminationGrid places the SH grid's points;
// refused where it would not fit in half the machine's memory.
DirectionalGrid makeDirectionalGrid(const Scene& scene, int resolution, int m, uint32_t seed);

// The basis's sample budgets, on either device. The SH grid's ray budgets (gather_rays,
// refine_rays, max_gather_rays) are rays a point; here each is that many rays over the m
// directions, at least one sample of each.
inline int directionalSamples(int rays, int m) { return std::max(1, rays / std::max(1, m)); }
// Samples of every direction to add before a pass, with `done` already taken.
inline int directionalSamplesToAdd(const GridExecutorSettings& s, int m, int done) {
  const int limit = directionalSamples(s.maxGatherRays, m);
  return s.refineRays > 0 ? std::min(directionalSamples(s.refineRays, m), limit - done) : 0;
}
// The samples each direction's Sobol sequence is laid out for, refinement included.
inline int directionalSequenceLength(const GridExecutorSettings& s, int m) {
  return std::max(directionalSamples(s.gatherRays, m), directionalSamples(s.maxGatherRays, m));
}

// The log's line for a filled grid: its points, directions, samples, rays, time and size.
void logDirectionalGrid(const DirectionalGrid& grid, const GridBuildStats& stats);

}  // namespace envgi
