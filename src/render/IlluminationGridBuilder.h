// Fills the illumination grid on the CPU (oneTBB over grid points, Embree): gather rays from
// every point read the photon maps one bounce away, projected on L1 spherical harmonics.
#pragma once

#include "accel/EmbreeAccel.h"
#include "integrators/GridIntegrator.h"
#include "photon/PhotonMap.h"
#include "scene/Scene.h"

namespace envgi {

struct GridBuildStats {
  size_t points = 0, insidePoints = 0;
  uint64_t rays = 0;
  double seconds = 0.0;
};

// A grid over the scene's bounds with `resolution` points along its longest side.
IlluminationGrid makeIlluminationGrid(const Scene& scene, int resolution);

// Adds `rays` gather rays to every point (rays [first, first + rays) of each point's sequence,
// so calls can refine a grid progressively) and re-averages it.
void gatherIntoGrid(IlluminationGrid& grid, const Scene& scene, const EmbreeAccel& accel, const PhotonMap& global,
                    const PhotonMap& caustic, const ChainParams& cp, uint32_t seed, int first, int rays,
                    GridBuildStats* stats);

}  // namespace envgi
