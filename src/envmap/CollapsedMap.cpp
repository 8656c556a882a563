#include "envmap/CollapsedMap.h"

#include <algorithm>
#include <queue>
#include <stdexcept>
#include <string>

#include "sampling/Sampler.h"

namespace envgi {

namespace {

void requirePointCount(int n) {
  if (n < 1 || n > kMaxCollapsedPoints)
    throw std::runtime_error("point_count must be between 1 and " + std::to_string(kMaxCollapsedPoints) + ", not " +
                             std::to_string(n));
}

}  // namespace

std::vector<DirectionalLight> collapseByWeightedSampling(const EnvironmentMap& map, int n, uint32_t seed) {
  requirePointCount(n);
  EnvironmentMapView v = map.view();
  std::vector<DirectionalLight> out;
  out.reserve(size_t(n));
  Sampler smp;
  smp.type = SamplerType::Sobol;
  smp.spp = uint32_t(n);
  smp.seed = seed;
  for (int i = 0; i < n; ++i) {
    smp.start(0, uint32_t(i));
    EnvSample es = v.sample(EnvStrategy::Importance, smp.get2D());
    Color e = es.pdf > 0.f ? es.radiance / (es.pdf * float(n)) : Color(0.f);
    out.push_back({es.dir, e, 0.f, 0.f, es.pdf > 0.f ? 1.f / (es.pdf * float(n)) : 0.f});
  }
  return out;
}

namespace {

struct Region {
  int x0, y0, x1, y1;
  double power;
};

}  // namespace

std::vector<DirectionalLight> collapseByMedianCut(const EnvironmentMap& map, int n) {
  requirePointCount(n);
  const Image& img = map.image();
  const int W = img.width, H = img.height;
  EnvironmentMapView v = map.view();
  // Luminance power of each pixel (L dOmega) and a summed-area table for region sums.
  std::vector<double> sat(size_t(W + 1) * (H + 1), 0.0);
  auto pixelOmega = [&](int y) { return (2.0 * kPi / W) * (kPi / H) * std::sin(kPi * (y + 0.5) / H); };
  auto at = [&](int x, int y) -> double& { return sat[size_t(y) * (W + 1) + x]; };
  for (int y = 0; y < H; ++y)
    for (int x = 0; x < W; ++x) {
      Color c = img.at(x, y);
      at(x + 1, y + 1) = luminance(c) * pixelOmega(y) + at(x, y + 1) + at(x + 1, y) - at(x, y);
    }
  auto sum = [&](int x0, int y0, int x1, int y1) { return at(x1, y1) - at(x0, y1) - at(x1, y0) + at(x0, y0); };
  // Split the most powerful region until there are n (a region of one pixel stays whole).
  auto cmp = [](const Region& a, const Region& b) { return a.power < b.power; };
  std::priority_queue<Region, std::vector<Region>, decltype(cmp)> heap(cmp);
  std::vector<Region> done;
  heap.push({0, 0, W, H, sum(0, 0, W, H)});
  while (!heap.empty() && int(heap.size() + done.size()) < n) {
    Region r = heap.top();
    heap.pop();
    int w = r.x1 - r.x0, h = r.y1 - r.y0;
    if (w * h <= 1) {
      done.push_back(r);
      continue;
    }
    // Longer side in angle: width in phi shrinks with sin(theta) at the region's middle row.
    double sinMid = std::sin(kPi * (0.5 * (r.y0 + r.y1)) / H);
    bool cutX = h == 1 || (w > 1 && double(w) * 2.0 * sinMid >= double(h));
    int lo = cutX ? r.x0 + 1 : r.y0 + 1, hi = cutX ? r.x1 - 1 : r.y1 - 1, cut = lo;
    // The cut where the first part holds half the power (binary search on the prefix sums).
    while (lo <= hi) {
      int mid = (lo + hi) / 2;
      double part = cutX ? sum(r.x0, r.y0, mid, r.y1) : sum(r.x0, r.y0, r.x1, mid);
      if (part < 0.5 * r.power) {
        cut = mid;
        lo = mid + 1;
      } else {
        cut = mid;
        hi = mid - 1;
      }
    }
    Region a = r, b = r;
    if (cutX) a.x1 = b.x0 = cut;
    else a.y1 = b.y0 = cut;
    a.power = sum(a.x0, a.y0, a.x1, a.y1);
    b.power = sum(b.x0, b.y0, b.x1, b.y1);
    heap.push(a);
    heap.push(b);
  }
  while (!heap.empty()) {
    done.push_back(heap.top());
    heap.pop();
  }
  std::vector<DirectionalLight> out;
  for (const Region& r : done) {
    Color e(0.f);
    double cx = 0.0, cy = 0.0, wsum = 0.0, omega = 0.0;
    for (int y = r.y0; y < r.y1; ++y)
      for (int x = r.x0; x < r.x1; ++x) {
        Color c = img.at(x, y);
        double om = pixelOmega(y), w = luminance(c) * om;
        e += c * float(om);
        omega += om;
        cx += w * (x + 0.5);
        cy += w * (y + 0.5);
        wsum += w;
      }
    if (wsum <= 0.0) {  // a black region: its centre
      cx = 0.5 * (r.x0 + r.x1);
      cy = 0.5 * (r.y0 + r.y1);
    } else {
      cx /= wsum;
      cy /= wsum;
    }
    Vec3f dir = v.fromLocal(EnvironmentMapView::uvToDir(Vec2f(float(cx / W), float(cy / H))));
    out.push_back({dir, e * v.scale, 0.f, 0.f, float(omega)});
  }
  return out;
}

}  // namespace envgi
