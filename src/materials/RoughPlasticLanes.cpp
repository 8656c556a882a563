#include "materials/RoughPlasticLanes.h"

#include "core/Lanes.h"

namespace envgi {

namespace {

// A two-sided BSDF's wo seen from the front (sampleInFrame's flip).
inline float frontZ(bool twoSided, float z) { return twoSided && z < 0.f ? -z : z; }

// Rough plastic's sample (detail::roughPlasticDisk, roughPlasticDirection and the rest) in
// steps, each a loop over the lanes. Where a direction falls among the coat's table nodes is
// kept in arrays (at, share) from one loop to the next (coatPlace). The material's members
// are read from a copy, which the arrays written cannot alias; it has its tables
// (RoughPlasticLanes::takes), which is said, so that the branches to the smooth coat's Fresnel terms go.
ENVGI_LANES void coatPlaces(int n, const float* __restrict z, float* __restrict z2, bool twoSided,
                            int* __restrict at, float* __restrict share) {
  for (int i = 0; i < n; ++i) {
    const float c = frontZ(twoSided, z[i]);
    const CoatPlace p = coatPlace(c);
    z2[i] = c, at[i] = p.i, share[i] = p.t;
  }
}

// wo's coat reflectance fo, the lobe, and the lobe's draw stretched over its share (into u0s).
ENVGI_LANES void roughPlasticLobes(int n, const Bsdf& bsdf, const CoatNode& node, const int* __restrict at,
                                   const float* __restrict share, const float* __restrict u0, float* __restrict fo,
                                   float* __restrict u0s, float* __restrict coatLobe) {
  const Bsdf b = bsdf;
  const CoatNode coat = node;
  if (b.coatNodes <= 0) __builtin_unreachable();
  for (int i = 0; i < n; ++i) {
    const float f = detail::roughCoatReflectanceAt(coat, CoatPlace{at[i], share[i]});
    const float ps = detail::plasticSpecularProb(b, f);
    fo[i] = f, u0s[i] = detail::plasticLobeDraw(ps, u0[i]), coatLobe[i] = u0[i] < ps ? 1.f : 0.f;
  }
}

// Then the disk point in polar form, in a loop of its own: in one with the stretch, GCC carried
// the stretch's clamp into a choice between masks, which it does not vectorise.
ENVGI_LANES void roughPlasticDisks(int n, const float* __restrict u0s, const float* __restrict u1,
                                   const float* __restrict coatLobe, float* __restrict r, float* __restrict angle) {
  for (int i = 0; i < n; ++i) {
    const PolarPoint p = detail::roughPlasticDisk(coatLobe[i] > 0.5f, Vec2f(u0s[i], u1[i]));
    r[i] = p.r, angle[i] = p.angle;
  }
}

// The direction from the disk point (front side), and where it falls among the nodes.
ENVGI_LANES void roughPlasticDirections(int n, const MicrofacetDistribution& dist, const float* __restrict wx,
                                        const float* __restrict wy, const float* __restrict wz,
                                        const float* __restrict diskX, const float* __restrict diskY,
                                        const float* __restrict coatLobe, float* __restrict ix, float* __restrict iy,
                                        float* __restrict iz, int* __restrict at, float* __restrict share) {
  const MicrofacetDistribution d{dist.alphaX, dist.alphaY, MicrofacetType::GGX};  // takes(): GGX
  for (int i = 0; i < n; ++i) {
    const Vec3f wi = detail::roughPlasticDirection(d, Vec3f(wx[i], wy[i], wz[i]), Vec2f(diskX[i], diskY[i]),
                                                   coatLobe[i] > 0.5f);
    const CoatPlace p = coatPlace(wi.z);
    ix[i] = wi.x, iy[i] = wi.y, iz[i] = wi.z, at[i] = p.i, share[i] = p.t;
  }
}

// The sample's density and weight (finishSample's), sampleInFrame's checks, and the flip back.
// The material's `nonlinear` is a constant of each instance, as mapLookups' flags are.
template <bool Nonlinear>
ENVGI_LANES void roughPlasticValues(int n, const Bsdf& bsdf, const CoatNode& node, const MicrofacetDistribution& dist,
                                    const float* __restrict wx, const float* __restrict wy,
                                    const float* __restrict wz, const float* __restrict fo,
                                    const float* __restrict zGiven, const int* __restrict at,
                                    const float* __restrict share, float* __restrict ix, float* __restrict iy,
                                    float* __restrict iz, float* __restrict fr, float* __restrict fg,
                                    float* __restrict fb, float* __restrict pdf, unsigned char* __restrict ok) {
  Bsdf b = bsdf;
  b.nonlinear = Nonlinear;
  const CoatNode coat = node;
  const MicrofacetDistribution d{dist.alphaX, dist.alphaY, MicrofacetType::GGX};
  if (b.coatNodes <= 0) __builtin_unreachable();
  for (int i = 0; i < n; ++i) {
    const Vec3f wo(wx[i], wy[i], wz[i]), wi(ix[i], iy[i], iz[i]);
    float p;
    const Color f = detail::roughPlasticTabledEvalPdf(
        b, d, coat, fo[i], coatTransmittanceAt(coat, CoatPlace{at[i], share[i]}), wo, wi, &p);
    const Color w = f / p;
    ok[i] = (wo.z > 0.f) & (wi.z > 0.f) & (p > 0.f) & isFiniteVec(w);
    const bool flip = b.twoSided && zGiven[i] < 0.f;
    iz[i] = flip ? -wi.z : wi.z;
    fr[i] = w.x, fg[i] = w.y, fb[i] = w.z, pdf[i] = p;
  }
}

// bsdfEvalPdf's evalPdfInFrame for rough plastic: the two-sided flip of both directions, each
// one's place among the coat's nodes (apart, as coatPlaces).
ENVGI_LANES void evalPlaces(int n, const float* __restrict zo, const float* __restrict zi, bool twoSided,
                            float* __restrict fzo, float* __restrict fzi, int* __restrict ato,
                            float* __restrict shareo, int* __restrict ati, float* __restrict sharei) {
  for (int i = 0; i < n; ++i) {
    const bool flip = twoSided && zo[i] < 0.f;
    const float co = flip ? -zo[i] : zo[i], ci = flip ? -zi[i] : zi[i];
    const CoatPlace po = coatPlace(co), pi = coatPlace(ci);
    fzo[i] = co, fzi[i] = ci, ato[i] = po.i, shareo[i] = po.t, ati[i] = pi.i, sharei[i] = pi.t;
  }
}

// Then the value and density, and whether both directions are above the (front) surface.
template <bool Nonlinear>
ENVGI_LANES void roughPlasticEvals(int n, const Bsdf& bsdf, const CoatNode& node, const MicrofacetDistribution& dist,
                                   const float* __restrict wx, const float* __restrict wy,
                                   const float* __restrict fzo, const float* __restrict ix,
                                   const float* __restrict iy, const float* __restrict fzi,
                                   const int* __restrict ato, const float* __restrict shareo,
                                   const int* __restrict ati, const float* __restrict sharei, float* __restrict fr,
                                   float* __restrict fg, float* __restrict fb, float* __restrict pdf,
                                   unsigned char* __restrict above) {
  Bsdf b = bsdf;
  b.nonlinear = Nonlinear;
  const CoatNode coat = node;
  const MicrofacetDistribution d{dist.alphaX, dist.alphaY, MicrofacetType::GGX};
  if (b.coatNodes <= 0) __builtin_unreachable();
  // The coat's tables are read only and apart from the arrays written, which GCC cannot see
  // through CoatNode's pointers here.
#if defined(__GNUC__) && !defined(__clang__)
#pragma GCC ivdep
#endif
  for (int i = 0; i < n; ++i) {
    const Vec3f wo(wx[i], wy[i], fzo[i]), wi(ix[i], iy[i], fzi[i]);
    float p;
    const Color f = detail::roughPlasticTabledEvalPdf(
        b, d, coat, detail::roughCoatReflectanceAt(coat, CoatPlace{ato[i], shareo[i]}),
        coatTransmittanceAt(coat, CoatPlace{ati[i], sharei[i]}), wo, wi, &p);
    // Written whatever the sides; the zeros below the surface are chosen when read (evalOf):
    // chosen here, GCC made the table's gathers conditional, which it does not vectorise.
    above[i] = (wo.z > 0.f) & (wi.z > 0.f);
    fr[i] = f.x, fg[i] = f.y, fb[i] = f.z, pdf[i] = p;
  }
}

}  // namespace

void RoughPlasticLanes::resize(size_t n) {
  if (woX.size() >= n) return;
  resizeShared(n);
  for (std::vector<float>* a : {&frontZ, &frontZi, &fo, &diskR, &diskAngle, &diskX, &diskY, &coatLobe, &coatShare,
                                &coatShareI})
    a->resize(n);
  coatAt.resize(n), coatAtI.resize(n);
}

void RoughPlasticLanes::sample(const Bsdf& b, int n) {
  const CoatNode coat = detail::roughCoat(b);
  const MicrofacetDistribution d = microfacet(b);
  // woZ keeps the given side; frontZ holds wo's z seen from the front. diskX holds the stretched
  // u.x until fromPolar's loop writes the disk points there.
  coatPlaces(n, woZ.data(), frontZ.data(), b.twoSided, coatAt.data(), coatShare.data());
  roughPlasticLobes(n, b, coat, coatAt.data(), coatShare.data(), u0.data(), fo.data(), diskX.data(), coatLobe.data());
  roughPlasticDisks(n, diskX.data(), u1.data(), coatLobe.data(), diskR.data(), diskAngle.data());
  for (int i = 0; i < n; ++i) {
    const Vec2f p = fromPolar({diskR[i], diskAngle[i]});
    diskX[i] = p.x, diskY[i] = p.y;
  }
  roughPlasticDirections(n, d, woX.data(), woY.data(), frontZ.data(), diskX.data(), diskY.data(), coatLobe.data(),
                         wiX.data(), wiY.data(), wiZ.data(), coatAt.data(), coatShare.data());
  auto values = b.nonlinear ? roughPlasticValues<true> : roughPlasticValues<false>;
  values(n, b, coat, d, woX.data(), woY.data(), frontZ.data(), fo.data(), woZ.data(), coatAt.data(), coatShare.data(),
         wiX.data(), wiY.data(), wiZ.data(), valueR.data(), valueG.data(), valueB.data(), pdf.data(), ok.data());
}

void RoughPlasticLanes::eval(const Bsdf& b, int n) {
  evalPlaces(n, woZ.data(), wiZ.data(), b.twoSided, frontZ.data(), frontZi.data(), coatAt.data(), coatShare.data(),
             coatAtI.data(), coatShareI.data());
  auto evals = b.nonlinear ? roughPlasticEvals<true> : roughPlasticEvals<false>;
  evals(n, b, detail::roughCoat(b), microfacet(b), woX.data(), woY.data(), frontZ.data(), wiX.data(), wiY.data(),
        frontZi.data(), coatAt.data(), coatShare.data(), coatAtI.data(), coatShareI.data(), valueR.data(),
        valueG.data(), valueB.data(), pdf.data(), ok.data());
}

}  // namespace envgi
