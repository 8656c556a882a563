// A photon map on the CPU: photons in a nanoflann kd-tree, and the radiance estimate of the
// paper's Eq. 10-12 from the k nearest photons.
#pragma once

#include <memory>
#include <vector>

#include "photon/IrradianceCache.h"
#include "photon/PhotonTracing.h"
#include "scene/IntegratorSettings.h"

namespace envgi {

struct PhotonLookup {
  int k = 120;              // photons in the estimate
  float maxRadius = 0.1f;   // search radius bound
  bool coneFilter = false;  // Jensen's cone filter, k = 1.1
};

class PhotonMap {
 public:
  PhotonMap();
  ~PhotonMap();
  PhotonMap(PhotonMap&&) noexcept;
  PhotonMap& operator=(PhotonMap&&) noexcept;

  // Takes the photons and builds the kd-tree.
  void build(std::vector<Photon> photons);
  size_t size() const { return photons_.size(); }
  const std::vector<Photon>& photons() const { return photons_; }
  size_t bytes() const;
  // The kd-tree's arrays per photon: the photon, its position and two indices (its nodes, about
  // one per 16 photons, and the irradiance cache come on top).
  static constexpr size_t kBytesPerPhoton = sizeof(Photon) + sizeof(Vec3f) + 2 * sizeof(uint32_t);

  // L_r(x, wo) = 1/(pi r^2) sum f_r(x, wp, wo) dPhi_p (Eq. 12), r the distance to the k-th
  // photon (Eq. 11), or maxRadius when fewer are within it. Photons arriving from behind the
  // surface are left out.
  Color estimate(const SceneView& sc, const SurfaceInteraction& si, Vec3f woWorld, const PhotonLookup& q) const;

  // Christensen's precomputation: irradiance from the k nearest photons at every stride-th
  // photon, so that a final-gather ray needs one nearest-neighbour lookup, not k. Three steps,
  // so that the caller picks the threads: begin (returns how many points), estimate each point
  // (any order, any thread), then end (builds their IrradianceCache).
  size_t beginIrradiance(int stride);
  void estimateIrradiance(size_t i, int k, float maxRadius);
  // The points of beginIrradiance in Morton order of their positions: estimated in this order,
  // consecutive queries walk the same kd-tree nodes and photons, which stay in cache (photons
  // are stored in the order they were shot, all over the scene). Changes no estimate.
  std::vector<uint32_t> irradianceOrder() const;
  void endIrradiance();
  // Irradiance near p on a surface facing n (IrradianceCacheView::irradiance).
  Color irradiance(Vec3f p, Vec3f n) const { return cache_.view().irradiance(p, n); }
  const IrradianceCache& irradianceCache() const { return cache_; }

 private:
  struct Index;
  std::vector<Photon> photons_;
  std::unique_ptr<Index> index_;
  std::vector<IrradiancePoint> irr_;  // being estimated, between begin and end
  IrradianceCache cache_;
  int irrStride_ = 0;
};

}  // namespace envgi
