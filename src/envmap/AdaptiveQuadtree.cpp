#include "envmap/AdaptiveQuadtree.h"

#include <algorithm>
#include <stdexcept>

namespace envgi {

AdaptiveQuadtree::AdaptiveQuadtree(const float* weight, int width, int height, int targetLeaves)
    : width_(width), height_(height) {
  if (targetLeaves < 1) throw std::invalid_argument("adaptive quadtree: target leaves must be >= 1");
  // Summed-area table in double: O(1) power of any pixel rectangle.
  std::vector<double> sat(size_t(width + 1) * (height + 1), 0.0);
  auto S = [&](int x, int y) -> double& { return sat[size_t(y) * (width + 1) + x]; };
  for (int y = 0; y < height; ++y)
    for (int x = 0; x < width; ++x)
      S(x + 1, y + 1) = weight[size_t(y) * width + x] + S(x, y + 1) + S(x + 1, y) - S(x, y);
  auto power = [&](const QuadtreeNode& n) { return S(n.x1, n.y1) - S(n.x0, n.y1) - S(n.x1, n.y0) + S(n.x0, n.y0); };
  double total = S(width, height);
  double limit = total / targetLeaves;

  // Square-ish roots: a 2:1 lat-long map starts as two square cells.
  int roots = std::max(1, width / std::max(1, height));
  for (int r = 0; r < roots; ++r) {
    int x0 = r * width / roots, x1 = (r + 1) * width / roots;
    nodes_.push_back({x0, 0, x1, height, -1, 0, -1});
  }
  rootCount_ = roots;
  // Breadth-first, so children of a node are contiguous.
  for (size_t i = 0; i < nodes_.size(); ++i) {
    QuadtreeNode n = nodes_[i];
    int w = n.x1 - n.x0, h = n.y1 - n.y0;
    bool split = total > 0.0 && power(n) > limit && (w > 1 || h > 1);
    if (!split) continue;
    int xm = w > 1 ? n.x0 + w / 2 : n.x1, ym = h > 1 ? n.y0 + h / 2 : n.y1;
    int first = int(nodes_.size());
    int xs[3] = {n.x0, xm, n.x1}, ys[3] = {n.y0, ym, n.y1};
    int count = 0;
    for (int cy = 0; cy < 2; ++cy)
      for (int cx = 0; cx < 2; ++cx) {
        if (xs[cx] == xs[cx + 1] || ys[cy] == ys[cy + 1]) continue;
        nodes_.push_back({xs[cx], ys[cy], xs[cx + 1], ys[cy + 1], -1, 0, -1});
        ++count;
      }
    nodes_[i].firstChild = first;
    nodes_[i].childCount = count;
  }
  for (size_t i = 0; i < nodes_.size(); ++i) {
    QuadtreeNode& n = nodes_[i];
    if (n.firstChild >= 0) continue;
    n.leaf = int(leafNodes_.size());
    leafNodes_.push_back(int(i));
    double dphi = 2.0 * M_PI * double(n.x1 - n.x0) / width;
    double omega = dphi * (std::cos(M_PI * n.y0 / height) - std::cos(M_PI * n.y1 / height));
    leafSolidAngle_.push_back(float(omega));
  }
}

AdaptiveQuadtreeView AdaptiveQuadtree::view() const {
  return {nodes_.data(), leafNodes_.data(), leafSolidAngle_.data(), int(leafNodes_.size()), rootCount_, int(nodes_.size()), width_, height_};
}

}  // namespace envgi
