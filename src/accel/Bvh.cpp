#include "accel/Bvh.h"

#include <embree3/rtcore.h>

#include <chrono>
#include <stdexcept>

namespace envgi {

namespace {

// The builder's own tree, allocated from Embree's thread-local arenas and flattened after.
struct BuildNode {
  bool leaf;
};
struct BuildInner : BuildNode {
  BuildNode* child[2];
  RTCBounds bounds[2];
};
struct BuildLeaf : BuildNode {
  unsigned count;
  unsigned prims[1];  // `count` entries follow
};

void* createNode(RTCThreadLocalAllocator alloc, unsigned int, void*) {
  auto* n = static_cast<BuildInner*>(rtcThreadLocalAlloc(alloc, sizeof(BuildInner), 16));
  n->leaf = false;
  n->child[0] = n->child[1] = nullptr;
  return n;
}
void setChildren(void* node, void** children, unsigned int count, void*) {
  auto* n = static_cast<BuildInner*>(node);
  for (unsigned i = 0; i < count && i < 2; ++i) n->child[i] = static_cast<BuildNode*>(children[i]);
}
void setBounds(void* node, const RTCBounds** bounds, unsigned int count, void*) {
  auto* n = static_cast<BuildInner*>(node);
  for (unsigned i = 0; i < count && i < 2; ++i) n->bounds[i] = *bounds[i];
}
void* createLeaf(RTCThreadLocalAllocator alloc, const RTCBuildPrimitive* prims, size_t count, void*) {
  auto* l = static_cast<BuildLeaf*>(
      rtcThreadLocalAlloc(alloc, sizeof(BuildLeaf) + sizeof(unsigned) * (count > 0 ? count - 1 : 0), 16));
  l->leaf = true;
  l->count = unsigned(count);
  for (size_t i = 0; i < count; ++i) l->prims[i] = prims[i].primID;
  return l;
}

struct Flattener {
  const std::vector<BvhTriangle>& source;
  std::vector<BvhNode>& nodes;
  std::vector<BvhTriangle>& out;
  BvhBuildStats& stats;

  void setBox(BvhNode& n, const RTCBounds& b) {
    n.lo[0] = b.lower_x;
    n.lo[1] = b.lower_y;
    n.lo[2] = b.lower_z;
    n.hi[0] = b.upper_x;
    n.hi[1] = b.upper_y;
    n.hi[2] = b.upper_z;
  }
  // Fills node `at` (its box already set) from `b`; children go to the end, side by side.
  void fill(size_t at, const BuildNode* b, int depth) {
    stats.maxDepth = std::max(stats.maxDepth, depth);
    if (b->leaf) {
      auto* l = static_cast<const BuildLeaf*>(b);
      nodes[at].index = int32_t(out.size());
      nodes[at].count = int32_t(l->count);
      for (unsigned i = 0; i < l->count; ++i) out.push_back(source[l->prims[i]]);
      ++stats.leaves;
      return;
    }
    auto* in = static_cast<const BuildInner*>(b);
    size_t c = nodes.size();
    nodes.resize(c + 2);
    nodes[at].index = int32_t(c);
    nodes[at].count = 0;
    for (int k = 0; k < 2; ++k) setBox(nodes[c + k], in->bounds[k]);
    for (int k = 0; k < 2; ++k) fill(c + k, in->child[k], depth + 1);
  }
};

}  // namespace

Bvh::Bvh(const Scene& scene) {
  auto t0 = std::chrono::steady_clock::now();
  const SceneView& sv = scene.view();
  spheres_ = sv.spheres;
  sphereCount_ = sv.sphereCount;
  sphereGeomOffset_ = sv.meshCount;
  if (sv.hasMasks) masks_ = std::make_unique<SceneView>(sv);

  std::vector<BvhTriangle> tris;
  std::vector<RTCBuildPrimitive> prims;
  for (int g = 0; g < sv.meshCount; ++g) {
    const MeshView& m = sv.meshes[g];
    for (int p = 0; p < m.triangleCount; ++p) {
      Vec3f a = m.positions[m.indices[3 * p]], b = m.positions[m.indices[3 * p + 1]],
            c = m.positions[m.indices[3 * p + 2]];
      // An instance's triangles go into this one-level BVH as placed copies (the GPU's memory
      // grows with the instances, Embree's does not).
      if (m.toWorld) a = m.toWorld->point(a), b = m.toWorld->point(b), c = m.toWorld->point(c);
      tris.push_back({a, b - a, c - a, g, p});
      Vec3f lo = vmin(a, vmin(b, c)), hi = vmax(a, vmax(b, c));
      RTCBuildPrimitive bp;
      bp.lower_x = lo.x;
      bp.lower_y = lo.y;
      bp.lower_z = lo.z;
      bp.upper_x = hi.x;
      bp.upper_y = hi.y;
      bp.upper_z = hi.z;
      bp.geomID = 0;
      bp.primID = unsigned(tris.size() - 1);
      prims.push_back(bp);
    }
  }
  stats_.triangles = tris.size();
  if (!tris.empty()) {
    RTCDevice device = rtcNewDevice(nullptr);
    if (!device) throw std::runtime_error("cannot create an Embree device for the BVH build");
    RTCBVH bvh = rtcNewBVH(device);
    RTCBuildArguments args = rtcDefaultBuildArguments();
    args.buildQuality = RTC_BUILD_QUALITY_MEDIUM;
    args.maxBranchingFactor = 2;
    args.maxDepth = kBvhStackSize - 4;  // traversal's fixed stack holds one entry a level
    args.minLeafSize = 1;
    args.maxLeafSize = 4;
    args.traversalCost = 1.f;
    args.intersectionCost = 1.f;
    args.bvh = bvh;
    args.primitives = prims.data();
    args.primitiveCount = prims.size();
    args.primitiveArrayCapacity = prims.size();
    args.createNode = createNode;
    args.setNodeChildren = setChildren;
    args.setNodeBounds = setBounds;
    args.createLeaf = createLeaf;
    auto* root = static_cast<BuildNode*>(rtcBuildBVH(&args));
    if (!root) {
      rtcReleaseBVH(bvh);
      rtcReleaseDevice(device);
      throw std::runtime_error("the BVH build failed");
    }
    Vec3f lo(INFINITY), hi(-INFINITY);
    for (const BvhTriangle& t : tris) {
      lo = vmin(lo, vmin(t.v0, vmin(t.v0 + t.e1, t.v0 + t.e2)));
      hi = vmax(hi, vmax(t.v0, vmax(t.v0 + t.e1, t.v0 + t.e2)));
    }
    nodes_.reserve(2 * tris.size());
    triangles_.reserve(tris.size());
    nodes_.resize(1);
    RTCBounds rb{lo.x, lo.y, lo.z, 0.f, hi.x, hi.y, hi.z, 0.f};
    Flattener f{tris, nodes_, triangles_, stats_};
    f.setBox(nodes_[0], rb);
    f.fill(0, root, 0);
    rtcReleaseBVH(bvh);
    rtcReleaseDevice(device);
    nodes_.shrink_to_fit();
  }
  stats_.nodes = nodes_.size();
  stats_.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

BvhView Bvh::view() const {
  BvhView v;
  v.nodes = nodes_.data();
  v.triangles = triangles_.data();
  v.nodeCount = int(nodes_.size());
  v.spheres = spheres_;
  v.sphereCount = sphereCount_;
  v.sphereGeomOffset = sphereGeomOffset_;
  v.masks = masks_.get();
  return v;
}

}  // namespace envgi
