// Builds what the grid integrator reads (the paper's GPU steps, Section 3): the photon maps,
// then an illumination grid whose points gather rays that read the maps one bounce away,
// projected on L1 spherical harmonics. The fill here runs on the CPU (oneTBB, any tracer); a
// GPU driver runs the same gridPointGather in a kernel and hands its sums to finishGather.
#pragma once

#include <algorithm>
#include <atomic>

#include "accel/EmbreeAccel.h"
#include "integrators/GridIntegrator.h"
#include "photon/PhotonMap.h"
#include "render/PhotonShooter.h"
#include "scene/Scene.h"

namespace envgi {

struct GridBuildStats {
  size_t points = 0, insidePoints = 0;
  uint64_t rays = 0;
  double seconds = 0.0;
};

struct GridExecutorSettings {
  PhotonShootSettings photons;
  GridParams params;
  int resolution = 32;
  int gatherRays = 128;
  int refineRays = 0;      // added before every camera pass after the first
  int maxGatherRays = 128;
  uint32_t seed = 0;
  // Set (Ctrl-C): the gather stops within a point and throws RenderCancelled.
  const std::atomic<bool>* cancel = nullptr;
  // The length of each point's ray sequence: the most rays it will get.
  int sequenceLength() const { return refineRays > 0 ? std::max(maxGatherRays, gatherRays) : gatherRays; }
  // Rays to add before a camera pass, when the grid already has `done` a point.
  int raysToAdd(int done) const { return refineRays > 0 ? std::max(0, std::min(refineRays, maxGatherRays - done)) : 0; }
};

// The photon maps and the grid, with how long each took.
struct GridBuild {
  PhotonMap global, caustic;
  PhotonShootStats photonStats;
  IlluminationGrid grid;
  GridBuildStats gridStats;
};

// The grid's box: the scene's bounds with half a cell of margin (so surfaces on the bounds still
// have points on both sides), `resolution` points along the longest side. Both bases use it.
struct GridBox {
  Vec3f lo, hi;
  int nx, ny, nz;
};
GridBox gridBox(const Scene& scene, int resolution);

// A grid over the scene's bounds with `resolution` points along its longest side; refused
// (requireGridFits) where it would not fit in half the machine's memory.
IlluminationGrid makeIlluminationGrid(const Scene& scene, int resolution);

// Throws, naming the size and the memory, where nx x ny x nz points would take more than half
// of memoryBytes (0: unknown, never refused): 512 a side over a cube is 134 M points, 14.6 GB
// and hours of gathering, which should end with an error rather than swap or be killed.
void requireGridFits(int nx, int ny, int nz, double memoryBytes, int resolution);

// Adds `rays` gather rays to every point (rays [first, first + rays) of each point's sequence
// of s.sequenceLength(), so calls refine a grid progressively) and re-averages it.
template <class Tracer>
void gatherIntoGrid(IlluminationGrid& grid, const Scene& scene, const Tracer& tracer, const PhotonMap& global,
                    const PhotonMap& caustic, const GridExecutorSettings& s, int first, int rays,
                    GridBuildStats* stats);

// After every point got its gather sums (IlluminationGrid::accumulate): averages the grid and
// adds the fill's figures to *stats.
void finishGather(IlluminationGrid& grid, uint64_t rays, double seconds, GridBuildStats* stats);

// Photon maps (traced where s.photons.tracer says), then the grid filled on the CPU by tracer.
template <class Tracer>
void buildGridOnCpu(const Scene& scene, const Tracer& tracer, const GridExecutorSettings& s, GridBuild* out);

// One log line each for the photon maps and the grid.
void logGridBuild(const GridBuild& b, int gatherRays);

}  // namespace envgi
