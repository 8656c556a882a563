// The paper's "adaptive" baseline (its reference [10] gives no detail), built here as an
// energy-balanced quadtree over the lat-long map: a cell splits while it holds more than
// 1/targetLeaves of the map's power, a leaf is chosen with equal probability ("by count")
// and sampled uniformly in solid angle. Bright regions end up in many small leaves, so
// they get more samples, but the density is flat inside each leaf.
#pragma once

#include <vector>

#include "core/Vec.h"

namespace envgi {

struct QuadtreeNode {
  int x0, y0, x1, y1;  // pixel rectangle [x0,x1) x [y0,y1)
  int firstChild;      // -1 for a leaf
  int childCount;
  int leaf;            // leaf index, -1 for an inner node
};

struct AdaptiveQuadtreeView {
  const QuadtreeNode* nodes = nullptr;
  const int* leafNodes = nullptr;      // node index of each leaf
  const float* leafSolidAngle = nullptr;
  int leafCount = 0;
  int rootCount = 0;                   // the roots are nodes [0, rootCount)
  int nodeCount = 0;
  int width = 0, height = 0;

  // Leaf containing the pixel (px, py).
  ENVGI_HD int findLeaf(int px, int py) const {
    int n = -1;
    for (int r = 0; r < rootCount; ++r)
      if (px >= nodes[r].x0 && px < nodes[r].x1 && py >= nodes[r].y0 && py < nodes[r].y1) n = r;
    if (n < 0) return -1;
    while (nodes[n].firstChild >= 0) {
      int next = -1;
      for (int c = 0; c < nodes[n].childCount; ++c) {
        const QuadtreeNode& ch = nodes[nodes[n].firstChild + c];
        if (px >= ch.x0 && px < ch.x1 && py >= ch.y0 && py < ch.y1) next = nodes[n].firstChild + c;
      }
      if (next < 0) return -1;
      n = next;
    }
    return nodes[n].leaf;
  }

  // Returns (u, v) in the map's [0,1)^2 parameterisation; *pdf in solid angle.
  ENVGI_HD Vec2f sample(Vec2f u, float* pdf) const {
    float s = u.x * float(leafCount);
    int l = s < float(leafCount) ? int(s) : leafCount - 1;
    float ux = s - float(l);
    const QuadtreeNode& nd = nodes[leafNodes[l]];
    float u0 = float(nd.x0) / width, u1 = float(nd.x1) / width;
    float cos0 = std::cos(kPi * float(nd.y0) / height), cos1 = std::cos(kPi * float(nd.y1) / height);
    float uu = lerpf(ux, u0, u1);
    float cosTheta = lerpf(u.y, cos0, cos1);  // uniform in cos(theta): uniform in solid angle
    float vv = safeAcos(cosTheta) * kInvPi;
    vv = clampf(vv, float(nd.y0) / height, float(nd.y1) / height * kOneMinusEpsilon);
    if (pdf) *pdf = leafSolidAngle[l] > 0.f ? 1.f / (float(leafCount) * leafSolidAngle[l]) : 0.f;
    return {uu < kOneMinusEpsilon ? uu : kOneMinusEpsilon, vv};
  }

  ENVGI_HD float pdf(Vec2f uv) const {
    int px = clampi(int(uv.x * width), 0, width - 1), py = clampi(int(uv.y * height), 0, height - 1);
    int l = findLeaf(px, py);
    if (l < 0 || !(leafSolidAngle[l] > 0.f)) return 0.f;
    return 1.f / (float(leafCount) * leafSolidAngle[l]);
  }
};

class AdaptiveQuadtree {
 public:
  AdaptiveQuadtree() = default;
  // weight: per-pixel power (luminance x sin theta), row-major width x height.
  AdaptiveQuadtree(const float* weight, int width, int height, int targetLeaves);
  AdaptiveQuadtreeView view() const;
  int leafCount() const { return int(leafNodes_.size()); }

 private:
  std::vector<QuadtreeNode> nodes_;
  std::vector<int> leafNodes_;
  std::vector<float> leafSolidAngle_;
  int rootCount_ = 0, width_ = 0, height_ = 0;
};

}  // namespace envgi
