#include "materials/RoughConductorLanes.h"

#include "core/Lanes.h"

namespace envgi {

namespace {

// GGX's visible normal's disk point in polar form (MicrofacetDistribution::visibleDiskPolar).
ENVGI_LANES void conductorDisks(int n, const float* __restrict u0, const float* __restrict u1, float* __restrict r,
                                float* __restrict angle) {
  for (int i = 0; i < n; ++i) {
    const PolarPoint p = MicrofacetDistribution::visibleDiskPolar(Vec2f(u0[i], u1[i]));
    r[i] = p.r, angle[i] = p.angle;
  }
}

// The rest of sampleInFrame's rough conductor: wo seen from the front, the visible normal from
// the disk point, the mirrored direction, finishSample's value and density, the checks, and the
// flip back. The material's members are read from a copy, which the arrays written cannot alias.
ENVGI_LANES void conductorSamples(int n, const Bsdf& bsdf, const float* __restrict wx, const float* __restrict wy,
                                  const float* __restrict wz, const float* __restrict diskX,
                                  const float* __restrict diskY, float* __restrict ix, float* __restrict iy,
                                  float* __restrict iz, float* __restrict fr, float* __restrict fg,
                                  float* __restrict fb, float* __restrict pdf, unsigned char* __restrict ok) {
  const Bsdf b = bsdf;
  const MicrofacetDistribution d{b.alpha, b.alpha, MicrofacetType::GGX};  // takes(): isotropic GGX
  for (int i = 0; i < n; ++i) {
    const bool flip = b.twoSided && wz[i] < 0.f;
    const Vec3f wo(wx[i], wy[i], flip ? -wz[i] : wz[i]);
    const Vec3f wi = reflect(wo, d.visibleGgxFromDisk(wo, Vec2f(diskX[i], diskY[i])));
    float p;
    const Color f = detail::roughConductorEvalPdf(b, d, wo, wi, &p);
    const Color w = f / p;
    ok[i] = (wo.z > 0.f) & (wi.z > 0.f) & (p > 0.f) & isFiniteVec(w);
    ix[i] = wi.x, iy[i] = wi.y, iz[i] = flip ? -wi.z : wi.z;
    fr[i] = w.x, fg[i] = w.y, fb[i] = w.z, pdf[i] = p;
  }
}

// evalPdfInFrame's rough conductor: both directions seen from the front, then the value and
// density, which count where both are above the surface (above).
ENVGI_LANES void conductorEvals(int n, const Bsdf& bsdf, const float* __restrict wx, const float* __restrict wy,
                                const float* __restrict wz, const float* __restrict ix, const float* __restrict iy,
                                const float* __restrict iz, float* __restrict fr, float* __restrict fg,
                                float* __restrict fb, float* __restrict pdf, unsigned char* __restrict above) {
  const Bsdf b = bsdf;
  const MicrofacetDistribution d{b.alpha, b.alpha, MicrofacetType::GGX};
  for (int i = 0; i < n; ++i) {
    const bool flip = b.twoSided && wz[i] < 0.f;
    const Vec3f wo(wx[i], wy[i], flip ? -wz[i] : wz[i]), wi(ix[i], iy[i], flip ? -iz[i] : iz[i]);
    float p;
    const Color f = detail::roughConductorEvalPdf(b, d, wo, wi, &p);
    above[i] = (wo.z > 0.f) & (wi.z > 0.f);
    fr[i] = f.x, fg[i] = f.y, fb[i] = f.z, pdf[i] = p;
  }
}

}  // namespace

void RoughConductorLanes::resize(size_t n) {
  if (woX.size() >= n) return;
  resizeShared(n);
  for (std::vector<float>* a : {&diskR, &diskAngle, &diskX, &diskY}) a->resize(n);
}

void RoughConductorLanes::sample(const Bsdf& b, int n) {
  conductorDisks(n, u0.data(), u1.data(), diskR.data(), diskAngle.data());
  for (int i = 0; i < n; ++i) {
    const Vec2f p = fromPolar({diskR[i], diskAngle[i]});
    diskX[i] = p.x, diskY[i] = p.y;
  }
  conductorSamples(n, b, woX.data(), woY.data(), woZ.data(), diskX.data(), diskY.data(), wiX.data(), wiY.data(),
                   wiZ.data(), valueR.data(), valueG.data(), valueB.data(), pdf.data(), ok.data());
}

void RoughConductorLanes::eval(const Bsdf& b, int n) {
  conductorEvals(n, b, woX.data(), woY.data(), woZ.data(), wiX.data(), wiY.data(), wiZ.data(), valueR.data(),
                 valueG.data(), valueB.data(), pdf.data(), ok.data());
}

}  // namespace envgi
