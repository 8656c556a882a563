#include "accel/Bvh.h"

#include <embree3/rtcore.h>

#include <chrono>
#include <map>
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

namespace {
RTCBuildPrimitive buildPrimitive(Vec3f lo, Vec3f hi, size_t index) {
  RTCBuildPrimitive bp;
  bp.lower_x = lo.x;
  bp.lower_y = lo.y;
  bp.lower_z = lo.z;
  bp.upper_x = hi.x;
  bp.upper_y = hi.y;
  bp.upper_z = hi.z;
  bp.geomID = 0;
  bp.primID = unsigned(index);
  return bp;
}

// A mesh's triangles as BVH entries with their boxes, in the mesh's own space, tagged geomId.
void appendTriangles(const MeshView& m, int geomId, std::vector<BvhTriangle>* tris, std::vector<RTCBuildPrimitive>* prims) {
  for (int p = 0; p < m.triangleCount; ++p) {
    Vec3f a = m.positions[m.indices[3 * p]], b = m.positions[m.indices[3 * p + 1]], c = m.positions[m.indices[3 * p + 2]];
    tris->push_back({a, b - a, c - a, geomId, p});
    prims->push_back(buildPrimitive(vmin(a, vmin(b, c)), vmax(a, vmax(b, c)), tris->size() - 1));
  }
}

// Builds a tree over `entries` (prims[i] the box of entries[i]) and appends it to nodes and
// triangles; returns its root node.
int buildTree(const std::vector<BvhTriangle>& entries, std::vector<RTCBuildPrimitive>& prims, RTCDevice device,
              std::vector<BvhNode>& nodes_, std::vector<BvhTriangle>& triangles_, BvhBuildStats& stats_) {
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
  // The builder reorders (and may overwrite) the primitive array: the root's box is read first.
  Vec3f lo(INFINITY), hi(-INFINITY);
  for (const RTCBuildPrimitive& p : prims) {
    lo = vmin(lo, Vec3f(p.lower_x, p.lower_y, p.lower_z));
    hi = vmax(hi, Vec3f(p.upper_x, p.upper_y, p.upper_z));
  }
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
    throw std::runtime_error("the BVH build failed");
  }
  const size_t at = nodes_.size();
  nodes_.resize(at + 1);
  RTCBounds rb{lo.x, lo.y, lo.z, 0.f, hi.x, hi.y, hi.z, 0.f};
  Flattener f{entries, nodes_, triangles_, stats_};
  f.setBox(nodes_[at], rb);
  f.fill(at, root, 0);
  rtcReleaseBVH(bvh);
  return int(at);
}
}  // namespace

Bvh::Bvh(const Scene& scene) {
  auto t0 = std::chrono::steady_clock::now();
  const SceneView& sv = scene.view();
  spheres_ = sv.spheres;
  sphereCount_ = sv.sphereCount;
  sphereGeomOffset_ = sv.meshCount;
  if (sv.hasMasks) masks_ = std::make_unique<SceneView>(sv);

  // The scene's tree: the triangles of the meshes of their own, in world space, and one entry
  // per instance, boxed by its group mesh's box placed (its eight corners).
  std::vector<BvhTriangle> tris;
  std::vector<RTCBuildPrimitive> prims;
  std::vector<int> instanceOfGeom(size_t(sv.meshCount), -1);
  for (int g = 0; g < sv.meshCount; ++g) {
    const MeshView& m = sv.meshes[g];
    if (m.toWorld) {
      Vec3f lo(INFINITY), hi(-INFINITY);
      for (int i = 0; i < m.vertexCount; ++i) lo = vmin(lo, m.positions[i]), hi = vmax(hi, m.positions[i]);
      Vec3f wlo(INFINITY), whi(-INFINITY);
      for (int c = 0; c < 8 && lo.x <= hi.x; ++c) {
        Vec3f w = m.toWorld->point(Vec3f(c & 1 ? hi.x : lo.x, c & 2 ? hi.y : lo.y, c & 4 ? hi.z : lo.z));
        wlo = vmin(wlo, w), whi = vmax(whi, w);
      }
      if (!(wlo.x <= whi.x)) continue;  // an empty group mesh
      // Widened by a little: the corners are rounded, the triangles placed by the ray's inverse.
      Vec3f pad = (whi - wlo) * 1e-6f + Vec3f(1e-30f);
      instanceOfGeom[size_t(g)] = int(instances_.size());
      instances_.push_back({*m.toWorld, -1, g});
      tris.push_back({Vec3f(0.f), Vec3f(0.f), Vec3f(0.f), g, -1 - int32_t(instances_.size() - 1)});
      prims.push_back(buildPrimitive(wlo - pad, whi + pad, tris.size() - 1));
      continue;
    }
    appendTriangles(m, g, &tris, &prims);
  }
  if (!tris.empty()) {
    RTCDevice device = rtcNewDevice(nullptr);
    if (!device) throw std::runtime_error("cannot create an Embree device for the BVH build");
    try {
      nodes_.reserve(2 * tris.size());
      buildTree(tris, prims, device, nodes_, triangles_, stats_);
      // Each group mesh's own tree, once, in the group's space, for every instance of it.
      std::map<const Vec3f*, int> roots;
      for (BvhInstance& in : instances_) {
        const MeshView& m = sv.meshes[in.geomId];
        auto it = roots.find(m.positions);
        if (it == roots.end()) {
          std::vector<BvhTriangle> local;
          std::vector<RTCBuildPrimitive> lp;
          appendTriangles(m, -1, &local, &lp);
          it = roots.emplace(m.positions, buildTree(local, lp, device, nodes_, triangles_, stats_)).first;
          stats_.groupTriangles += local.size();
        }
        in.root = it->second;
      }
    } catch (...) {
      rtcReleaseDevice(device);
      throw;
    }
    rtcReleaseDevice(device);
    nodes_.shrink_to_fit();
  }
  stats_.triangles = triangles_.size() - instances_.size();
  stats_.instances = instances_.size();
  stats_.nodes = nodes_.size();
  stats_.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

BvhView Bvh::view() const {
  BvhView v;
  v.nodes = nodes_.data();
  v.triangles = triangles_.data();
  v.nodeCount = int(nodes_.size());
  v.instances = instances_.empty() ? nullptr : instances_.data();
  v.instanceCount = int(instances_.size());
  v.spheres = spheres_;
  v.sphereCount = sphereCount_;
  v.sphereGeomOffset = sphereGeomOffset_;
  v.masks = masks_.get();
  return v;
}

}  // namespace envgi
