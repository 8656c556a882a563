#include "render/DirectionalGridBuilder.h"

#include <spdlog/spdlog.h>

#include <cmath>

#include "core/PhysicalMemory.h"
#include "envmap/CollapsedMap.h"

namespace envgi {

void gridDirections(const Scene& scene, int m, uint32_t seed, std::vector<Vec3f>* dirs, std::vector<float>* share) {
  dirs->clear();
  share->clear();
  // Half the directions are the collapsed map's (Algorithm 1's draws), half a Fibonacci spiral
  // even over the sphere; each direction's share is 1 / (M p_mix), p_mix the two densities mixed
  // by their counts: the balance heuristic of Eq. 5-6 over the two sets. The map's draws alone
  // gave the map's dark half a few directions of huge share, and one of them, meeting a lit
  // surface, lit whole regions (the indirect light comes from surfaces, not from the map).
  const bool map = scene.env && scene.env->view().paperDist.integral() > 0.f;
  const int drawn = map ? m - m / 2 : 0, even = m - drawn;
  if (drawn > 0)
    for (const DirectionalLight& l : collapseByWeightedSampling(*scene.env, drawn, seed)) dirs->push_back(l.dir);
  for (int k = 0; k < even; ++k) {
    const float z = 1.f - 2.f * (float(k) + 0.5f) / float(even), r = std::sqrt(std::max(0.f, 1.f - z * z));
    const float phi = 2.39996323f * float(k);
    dirs->push_back(Vec3f(r * std::cos(phi), z, r * std::sin(phi)));
  }
  const EnvironmentMapView v = map ? scene.env->view() : EnvironmentMapView{};
  for (const Vec3f& d : *dirs) {
    const double pMix = (map ? double(drawn) * v.pdf(EnvStrategy::Algorithm1, d) : 0.0) + double(even) / (4.0 * M_PI);
    share->push_back(float(1.0 / pMix));  // 1 / (M p_mix), with M p_mix = sum of n_i p_i
  }
}

DirectionalGrid makeDirectionalGrid(const Scene& scene, int resolution, int m, uint32_t seed) {
  const GridBox b = gridBox(scene, resolution);
  const double bytes = double(b.nx) * b.ny * b.nz * double(DirectionalGrid::bytesPerPoint(m));
  requireFitsInHalfOfMemory(bytes, physicalMemoryBytes(), fmt::format("grid: {}x{}x{} points of {} directions would take", b.nx, b.ny, b.nz, m),
                            fmt::format("lower `resolution` ({}) or `directions` ({})", resolution, m));
  std::vector<Vec3f> dirs;
  std::vector<float> share;
  gridDirections(scene, m, seed, &dirs, &share);
  return DirectionalGrid(b.lo, b.hi, b.nx, b.ny, b.nz, std::move(dirs), std::move(share));
}

void logDirectionalGrid(const DirectionalGrid& grid, const GridBuildStats& stats) {
  const DirectionalGridView& v = grid.view();
  spdlog::info("grid: {}x{}x{} points x {} directions, {} samples each, {:.2f} M rays in {:.2f} s, {:.1f} MB", v.nx,
               v.ny, v.nz, v.m, grid.samplesPerDirection(), stats.rays / 1e6, stats.seconds, grid.bytes() / 1e6);
}

}  // namespace envgi
