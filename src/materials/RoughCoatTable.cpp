// The rough plastic coat's tables (materials/RoughCoat.h), built on the host once per
// (alpha, ior, distribution) and kept for the life of the process, so that a Bsdf can point
// at them whatever copies of scenes are made.
#include <spdlog/spdlog.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <deque>
#include <map>
#include <mutex>
#include <tuple>
#include <vector>

#include "materials/BsdfFactory.h"

namespace envgi {

namespace {

// Gauss-Legendre nodes and weights on (0, 1), by Newton's method on the Legendre polynomial,
// with the cosine and sine of pi times each node (the azimuths coatIntegral visits).
struct Quadrature {
  std::vector<double> x, w, cosPhi, sinPhi;
  explicit Quadrature(int n);
};

Quadrature::Quadrature(int n) : x(size_t(n)), w(size_t(n)), cosPhi(size_t(n)), sinPhi(size_t(n)) {
  for (int k = 0; k < n; ++k) {
    double t = std::cos(M_PI * (k + 0.75) / (n + 0.5)), dp = 1.0;
    for (int it = 0; it < 100; ++it) {
      double p0 = 1.0, p1 = t;
      for (int j = 2; j <= n; ++j) {
        double p2 = ((2.0 * j - 1.0) * t * p1 - (j - 1.0) * p0) / j;
        p0 = p1;
        p1 = p2;
      }
      dp = n * (t * p1 - p0) / (t * t - 1.0);
      double step = p1 / dp;
      t -= step;
      if (std::fabs(step) < 1e-15) break;
    }
    x[size_t(k)] = 0.5 * (1.0 - t);
    w[size_t(k)] = 1.0 / ((1.0 - t * t) * dp * dp);  // 2 / ((1 - t^2) P'^2), halved for (0, 1)
    cosPhi[size_t(k)] = std::cos(M_PI * x[size_t(k)]);
    sinPhi[size_t(k)] = std::sin(M_PI * x[size_t(k)]);
  }
}

// What microfacet m (facing wi) sends on: reflected, F G1(wo) above the surface; transmitted,
// (1 - F) G1(wt) below it.
float coatShare(const MicrofacetDistribution& d, Vec3f wi, Vec3f m, float eta, bool transmitted) {
  float cosIM = dot(wi, m);
  if (cosIM <= 0.f) return 0.f;
  float F = fresnelDielectric(cosIM, eta);
  if (!transmitted) {
    Vec3f wo = reflect(wi, m);
    return wo.z > 0.f ? F * d.G1(wo) : 0.f;
  }
  Vec3f wt;
  if (!refractDir(wi, m, eta, &wt) || wt.z >= 0.f || dot(wt, m) >= 0.f) return 0.f;
  return (1.f - F) * d.G1(wt);
}

// What the interface does with light arriving from wi (mu = wi.z > 0) at relative index eta:
// the share reflected, or the share transmitted, each over visible microfacets and masked on
// the way out (what Mitsuba's eval_reflectance and eval_transmittance tabulate), by
// Gauss-Legendre quadrature in the square of a warp onto microfacet normals. GGX: its visible
// normals, where nothing is cut off and no density is divided out. Beckmann, whose
// visible-normal warp is a Newton solve: D(m) cos(theta_m), with phi over half the circle (wi
// lies in the xz-plane, so the other half mirrors it), each m weighed by the visible-normal
// density over D cos, G1(wi) max(0, wi.m) / (mu cos theta_m).
double coatIntegral(const MicrofacetDistribution& d, float mu, float eta, bool transmitted, const Quadrature& q) {
  const std::vector<double>&x = q.x, &w = q.w;
  const int n = int(x.size());
  Vec3f wi(std::sqrt(std::max(0.f, 1.f - mu * mu)), 0.f, mu);
  double sum = 0.0;
  if (d.type == MicrofacetType::GGX) {
    for (int i = 0; i < n; ++i)
      for (int j = 0; j < n; ++j) {
        Vec3f m = d.sampleVisible(wi, Vec2f(float(x[size_t(i)]), float(x[size_t(j)])));
        sum += w[size_t(i)] * w[size_t(j)] * double(coatShare(d, wi, m, eta, transmitted));
      }
    return sum;
  }
  float g1i = d.G1(wi);
  double a2 = double(d.alphaX) * double(d.alphaX);
  for (int i = 0; i < n; ++i) {
    double tan2 = -a2 * std::log1p(-x[size_t(i)]);
    double cosM = 1.0 / std::sqrt(1.0 + tan2), sinM = std::sqrt(tan2) * cosM;
    for (int j = 0; j < n; ++j) {
      Vec3f m(float(sinM * q.cosPhi[size_t(j)]), float(sinM * q.sinPhi[size_t(j)]), float(cosM));
      float cosIM = dot(wi, m);
      if (cosIM <= 0.f) continue;
      sum += w[size_t(i)] * w[size_t(j)] * double(g1i * cosIM * coatShare(d, wi, m, eta, transmitted)) /
             (double(mu) * cosM);
    }
  }
  return sum;
}

// The layout RoughCoat.h reads, one node per roughness in alphas: every (node, mu) pair's two
// integrals in parallel, then each node's hemispherical means.
std::vector<float> buildTable(const std::vector<float>& alphas, float ior, MicrofacetType type) {
  // 32 and 64 nodes a side leave t and Fdr_int within 1e-4 of 512 and 1024 (GGX and Beckmann
  // at alpha 0.1 and 0.3); from inside, total internal reflection makes the integrand jump.
  static const Quadrature outside(32), inside(64);
  const int nodes = int(alphas.size());
  std::vector<float> table(size_t(nodes) * kCoatStride), reflIn(size_t(nodes) * kCoatRes);
  auto mu = [](int i) { return std::max(1e-6f, float(i) / float(kCoatRes - 1)); };
  tbb::parallel_for(0, nodes * kCoatRes, [&](int k) {
    int j = k / kCoatRes, i = k % kCoatRes;
    MicrofacetDistribution d{alphas[size_t(j)], alphas[size_t(j)], type};
    table[size_t(j) * kCoatStride + size_t(i)] = float(coatIntegral(d, mu(i), ior, true, outside));
    reflIn[size_t(k)] = float(coatIntegral(d, mu(i), 1.f / ior, false, inside));
  });
  // Mitsuba's hemispherical averages: the mean over the same nodes of R mu (or t mu), doubled.
  for (int j = 0; j < nodes; ++j) {
    float* node = table.data() + size_t(j) * kCoatStride;
    double fdr = 0.0, tHemi = 0.0;
    for (int i = 0; i < kCoatRes; ++i) {
      fdr += double(reflIn[size_t(j) * kCoatRes + size_t(i)]) * mu(i);
      tHemi += double(node[i]) * mu(i);
    }
    node[kCoatRes] = float(2.0 * fdr / kCoatRes);
    node[kCoatRes + 1] = float(2.0 * tHemi / kCoatRes);
  }
  return table;
}

}  // namespace

const float* roughCoatTable(float alpha, float ior, MicrofacetType type, bool texturedAlpha, int* nodes) {
  static std::mutex lock;
  static std::map<std::tuple<float, float, int, bool>, const std::vector<float>*> cache;
  static std::deque<std::vector<float>> tables;  // never moves what it holds
  *nodes = texturedAlpha ? kCoatAlphaNodes : 1;
  auto key = std::make_tuple(texturedAlpha ? 0.f : alpha, ior, int(type), texturedAlpha);
  std::lock_guard<std::mutex> hold(lock);
  auto it = cache.find(key);
  if (it != cache.end()) return it->second->data();
  std::vector<float> alphas;
  for (int j = 0; j < *nodes; ++j) alphas.push_back(texturedAlpha ? coatNodeAlpha(j, *nodes) : alpha);
  auto start = std::chrono::steady_clock::now();
  std::vector<float>& t = tables.emplace_back(buildTable(alphas, ior, type));
  double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  // A textured alpha's 32 nodes take a few tenths of a second: say where the time went.
  spdlog::log(seconds > 0.1 ? spdlog::level::info : spdlog::level::debug,
              "rough plastic coat tables (ior {:.4g}, {}, {}): {} node{} in {:.2f} s", ior,
              type == MicrofacetType::GGX ? "ggx" : "beckmann", texturedAlpha ? "textured alpha" : fmt::format("alpha {:.4g}", alpha),
              *nodes, *nodes == 1 ? "" : "s", seconds);
  cache.emplace(key, &t);
  return t.data();
}

void attachRoughCoat(Bsdf& b) {
  if (b.type != BsdfType::RoughPlastic) return;
  setBsdfCoatTable(b, roughCoatTable(b.alpha, b.ior, b.distribution, b.alphaTexture >= 0, &b.coatNodes));
}

}  // namespace envgi
