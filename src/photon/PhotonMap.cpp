#include "photon/PhotonMap.h"

#include <nanoflann.hpp>
#include <tbb/parallel_sort.h>

#include <algorithm>
#include <cmath>

namespace envgi {

namespace {
// The photons' positions as nanoflann reads them.
struct Cloud {
  const std::vector<Vec3f>* pts;
  size_t kdtree_get_point_count() const { return pts->size(); }
  float kdtree_get_pt(size_t i, size_t dim) const { return (*pts)[i][int(dim)]; }
  template <class BBox>
  bool kdtree_get_bbox(BBox&) const {
    return false;
  }
};
using Tree = nanoflann::KDTreeSingleIndexAdaptor<nanoflann::L2_Simple_Adaptor<float, Cloud>, Cloud, 3, uint32_t>;
}  // namespace

// The kd-tree over the photons' positions, kept in the order of the tree's leaves: a leaf's
// points are then neighbours in memory, where in the photons' own (shot) order each one the
// search looked at was a cache miss of its own.
struct PhotonMap::Index {
  std::vector<Vec3f> pos;          // after the build: in leaf order
  std::vector<uint32_t> photonOf;  // leaf order -> index in the map's photons
  Cloud cloud;
  Tree tree;
  explicit Index(const std::vector<Photon>& photons)
      : pos(photons.size()), cloud{&pos},
        // Built below, once the positions are in: the constructor would otherwise build it over
        // zeros first (it used to build twice, over the photons).
        tree(3, cloud, nanoflann::KDTreeSingleIndexAdaptorParams(16, nanoflann::KDTreeSingleIndexAdaptorFlags::SkipInitialBuildIndex)) {
    for (size_t i = 0; i < photons.size(); ++i) pos[i] = photons[i].p;
    tree.buildIndex();
    // The built tree's leaves address positions through vAcc: lay the positions out in that
    // order and make vAcc the identity. Nodes and bounds stay as built, so every search visits
    // the same points in the same order as before.
    photonOf.assign(tree.vAcc.begin(), tree.vAcc.end());
    for (size_t j = 0; j < pos.size(); ++j) pos[j] = photons[photonOf[j]].p;
    for (size_t j = 0; j < pos.size(); ++j) tree.vAcc[j] = uint32_t(j);
  }

  // The k nearest photons within squared distance maxR2 (inclusive), nearest first, as indices
  // into the map's photons: knnSearch's answer less the farther ones, which every caller drops.
  // The search starts with maxR2 as its bound instead of infinity, so a query far from every
  // photon (a floor point under a caustic map that lives on the glass's shadow) no longer walks
  // the tree out to k photons it would drop. *r2 is the estimate's squared radius (Eq. 11): the
  // k-th photon's distance, or maxR2 where fewer lie within it.
  size_t nearestWithin(const float q[3], size_t k, float maxR2, uint32_t* idx, float* d2, float* r2) const {
    nanoflann::KNNResultSet<float, uint32_t> found(k);
    found.init(idx, d2);
    d2[k - 1] = std::nextafter(maxR2, INFINITY);  // the tree takes a point if its distance is below this
    tree.findNeighbors(found, q, nanoflann::SearchParams());
    const size_t n = found.size();
    for (size_t i = 0; i < n; ++i) idx[i] = photonOf[idx[i]];
    *r2 = n < k ? maxR2 : d2[n - 1];
    return n;
  }
};

PhotonMap::PhotonMap() = default;
PhotonMap::~PhotonMap() = default;
PhotonMap::PhotonMap(PhotonMap&&) noexcept = default;
PhotonMap& PhotonMap::operator=(PhotonMap&&) noexcept = default;

void PhotonMap::build(std::vector<Photon> photons) {
  photons_ = std::move(photons);
  index_.reset();
  if (!photons_.empty()) index_ = std::make_unique<Index>(photons_);
}

size_t PhotonMap::bytes() const {
  // The kd-tree holds a position and two indices per point plus nodes of about 16 points each.
  size_t n = photons_.size();
  return n * kBytesPerPhoton + n / 16 * 48 + cache_.bytes();
}

size_t PhotonMap::beginIrradiance(int stride) {
  irr_.clear();
  cache_ = IrradianceCache();
  irrStride_ = stride;
  if (!index_ || stride < 1) return 0;
  irr_.resize((photons_.size() + size_t(stride) - 1) / size_t(stride));
  return irr_.size();
}

void PhotonMap::estimateIrradiance(size_t i, int k, float maxRadius) {
  const Photon& c = photons_[i * size_t(irrStride_)];
  size_t kk = size_t(std::min(std::max(k, 1), kMaxPhotonLookup));
  float maxR2 = maxRadius * maxRadius;
  uint32_t idx[kMaxPhotonLookup];
  float d2[kMaxPhotonLookup];
  float q[3] = {c.p.x, c.p.y, c.p.z};
  float r2;
  size_t found = index_->nearestWithin(q, kk, maxR2, idx, d2, &r2);
  Color sum(0.f);
  for (size_t j = 0; j < found; ++j) {
    const Photon& ph = photons_[idx[j]];
    if (dot(ph.n, c.n) > kSameSurfaceCos) sum += ph.power;
  }
  irr_[i] = {c.p, c.n, found > 0 ? sum / (kPi * r2) : Color(0.f), r2};
}

namespace {
// 10 bits of x spread to every third bit (a Morton code's share of one axis).
uint32_t spreadBits10(uint32_t x) {
  x &= 0x3ffu;
  x = (x | (x << 16)) & 0x030000ffu;
  x = (x | (x << 8)) & 0x0300f00fu;
  x = (x | (x << 4)) & 0x030c30c3u;
  x = (x | (x << 2)) & 0x09249249u;
  return x;
}
}  // namespace

std::vector<uint32_t> PhotonMap::irradianceOrder() const {
  const size_t n = irr_.size();
  Vec3f lo(INFINITY), hi(-INFINITY);
  for (size_t i = 0; i < n; ++i) {
    const Vec3f p = photons_[i * size_t(irrStride_)].p;
    lo = vmin(lo, p);
    hi = vmax(hi, p);
  }
  // (code << 32 | index): one sort key, ties kept in index order.
  std::vector<uint64_t> keys(n);
  for (size_t i = 0; i < n; ++i) {
    const Vec3f p = photons_[i * size_t(irrStride_)].p;
    auto cell = [](float v, float a, float b) {
      float t = (v - a) / (b - a);  // NaN where b == a (or the box is infinite): cell 0
      return t > 0.f ? uint32_t(fminf(t, 1.f) * 1023.f) : 0u;
    };
    const uint32_t code = spreadBits10(cell(p.x, lo.x, hi.x)) | spreadBits10(cell(p.y, lo.y, hi.y)) << 1 |
                          spreadBits10(cell(p.z, lo.z, hi.z)) << 2;
    keys[i] = uint64_t(code) << 32 | uint64_t(i);
  }
  tbb::parallel_sort(keys.begin(), keys.end());
  std::vector<uint32_t> order(n);
  for (size_t i = 0; i < n; ++i) order[i] = uint32_t(keys[i]);
  return order;
}

void PhotonMap::endIrradiance() {
  cache_.build(std::move(irr_));
  irr_.clear();
}

Color PhotonMap::estimate(const SceneView& sc, const SurfaceInteraction& si, Vec3f woWorld, const PhotonLookup& q) const {
  if (!index_ || q.k <= 0) return Color(0.f);
  size_t k = size_t(q.k);
  uint32_t idx[kMaxPhotonLookup];
  float d2[kMaxPhotonLookup];
  if (k > size_t(kMaxPhotonLookup)) k = size_t(kMaxPhotonLookup);
  float query[3] = {si.p.x, si.p.y, si.p.z};
  float maxR2 = q.maxRadius * q.maxRadius;
  float r2;
  size_t found = index_->nearestWithin(query, k, maxR2, idx, d2, &r2);
  if (found == 0) return Color(0.f);
  BsdfScratch textured;
  const Bsdf& bsdf = sc.bsdfAt(si, &textured);
  Vec3f woLocal = si.shading.toLocal(woWorld);
  float r = std::sqrt(r2);
  const float coneK = 1.1f;
  Color sum(0.f);
  for (size_t i = 0; i < found; ++i) {
    const Photon& ph = photons_[idx[i]];
    Vec3f wiLocal = si.shading.toLocal(ph.wi);
    if (dot(ph.wi, si.ng) * dot(woWorld, si.ng) <= 0.f && !bsdfTransmits(bsdf)) continue;
    float c = std::fabs(wiLocal.z);
    if (c <= 0.f) continue;
    Color f = bsdfEval(bsdf, woLocal, wiLocal) / c;  // eval() carries |cos|; Eq. 12 wants f_r
    float w = q.coneFilter ? 1.f - std::sqrt(d2[i]) / (coneK * r) : 1.f;
    sum += f * ph.power * w;
  }
  float norm = q.coneFilter ? (1.f - 2.f / (3.f * coneK)) : 1.f;
  return sum / (kPi * r2 * norm);
}

}  // namespace envgi
