// The host side of the BVH that the CPU and the GPU both traverse: built by Embree's binned
// SAH builder (rtcBuildBVH), flattened depth-first into 32-byte nodes with siblings adjacent.
#pragma once

#include <memory>
#include <vector>

#include "accel/BvhView.h"
#include "scene/Scene.h"

namespace envgi {

struct BvhBuildStats {
  double seconds = 0.0;
  size_t triangles = 0, nodes = 0, leaves = 0;
  size_t instances = 0, groupTriangles = 0;  // placements, and the triangles of their group meshes' trees
  int maxDepth = 0;
  size_t bytes() const { return nodes * sizeof(BvhNode) + (triangles + instances) * sizeof(BvhTriangle) + instances * sizeof(BvhInstance); }
};

class Bvh {
 public:
  explicit Bvh(const Scene& scene);
  // The view points into this object and into the scene's spheres (and, where the scene has
  // masks, its materials and textures).
  BvhView view() const;
  const BvhBuildStats& stats() const { return stats_; }
  const std::vector<BvhNode>& nodes() const { return nodes_; }
  const std::vector<BvhTriangle>& triangles() const { return triangles_; }
  const std::vector<BvhInstance>& instances() const { return instances_; }

 private:
  std::vector<BvhNode> nodes_;
  std::vector<BvhTriangle> triangles_;  // the scene's tree's leaves, then each group mesh's tree's
  std::vector<BvhInstance> instances_;
  const SphereView* spheres_ = nullptr;
  int sphereCount_ = 0, sphereGeomOffset_ = 0;
  std::unique_ptr<SceneView> masks_;  // a copy of the scene's view where it has masks (BvhView::masks)
  BvhBuildStats stats_;
};

}  // namespace envgi
