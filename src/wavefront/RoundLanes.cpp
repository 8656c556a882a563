#include "wavefront/RoundLanes.h"

namespace envgi {

namespace {

// Each loop is built three times, for AVX-512 (x86-64-v4), for AVX2 and for the baseline, and
// the loader picks one for the machine (GCC's target_clones). This file is built without FMA
// contraction (src/CMakeLists.txt), so a lane's arithmetic is the scalar code's to the bit.
// Sobol's 64-bit mixing has a vector multiply only in AVX-512 (vpmullq; AVX2 builds it from
// three 32-bit ones): the AVX-512 clones took the buddha bench's share from 55.5 to 56.9%.
// The baseline (SSE2) has neither a 32-bit nor a 64-bit vector multiply.
#if defined(__x86_64__) && defined(__GNUC__) && !defined(__clang__)
#define ENVGI_LANES __attribute__((target_clones("arch=x86-64-v4", "avx2", "default")))
#elif defined(__x86_64__) && defined(__clang__)
#define ENVGI_LANES __attribute__((target_clones("avx2", "default")))
#else
#define ENVGI_LANES
#endif

ENVGI_LANES void pixelHashes(int n, const int* __restrict px, const int* __restrict py, uint64_t width, uint32_t seed,
                             uint64_t* __restrict h) {
  for (int i = 0; i < n; ++i) h[i] = pixelHashOf(uint64_t(py[i]) * width + uint64_t(px[i]), seed);
}

ENVGI_LANES void sobolDraws(int n, const uint64_t* __restrict h, uint32_t d, uint32_t index, IndexBlock block,
                            uint32_t blockSeed, float* __restrict u0, float* __restrict u1) {
  for (int i = 0; i < n; ++i) {
    const Vec2f u = sobolDraw2D(h[i], d, index, block, blockSeed);
    u0[i] = u.x, u1[i] = u.y;
  }
}

// As sobolDraws, each lane at its own dimension pair: d[i] + at.
ENVGI_LANES void sobolDrawsAt(int n, const uint64_t* __restrict h, const uint32_t* __restrict d, uint32_t at,
                              uint32_t index, IndexBlock block, uint32_t blockSeed, float* __restrict u0,
                              float* __restrict u1) {
  for (int i = 0; i < n; ++i) {
    const Vec2f u = sobolDraw2D(h[i], d[i] + at, index, block, blockSeed);
    u0[i] = u.x, u1[i] = u.y;
  }
}

// The box filter's offsets in place of the draws (sampleBoxFilter).
ENVGI_LANES void boxOffsets(int n, float* __restrict u0, float* __restrict u1, float* __restrict w) {
  for (int i = 0; i < n; ++i) {
    const FilterSample fs = sampleBoxFilter(Vec2f(u0[i], u1[i]));
    u0[i] = fs.offset.x, u1[i] = fs.offset.y, w[i] = fs.weight;
  }
}

struct RayLanes {
  float *__restrict ox, *__restrict oy, *__restrict oz, *__restrict dx, *__restrict dy, *__restrict dz,
      *__restrict tMax;
  void put(int i, const Ray& r) const {
    ox[i] = r.o.x, oy[i] = r.o.y, oz[i] = r.o.z, dx[i] = r.d.x, dy[i] = r.d.y, dz[i] = r.d.z, tMax[i] = r.tMax;
  }
};

// sampleCameraRay's image position: the pixel's centre moved by the filter's offset.
inline float imageX(const int* px, const float* off, int i) { return float(px[i]) + 0.5f + off[i]; }

// generateRay's pinhole, its branches taken outside the loop.
ENVGI_LANES void pinholeRays(int n, const Camera& camera, const int* __restrict px, const int* __restrict py,
                             const float* __restrict o0, const float* __restrict o1, RayLanes out) {
  const Camera cam = camera;  // a copy, which the arrays written cannot alias
  for (int i = 0; i < n; ++i)
    out.put(i, cam.pinholeRay(cam.imagePlanePoint(imageX(px, o0, i), imageX(py, o1, i))));
}

ENVGI_LANES void mapCoordinates(int n, const Transform& toWorld, const float* __restrict d0,
                                const float* __restrict d1, const float* __restrict d2, float* __restrict us,
                                float* __restrict vs) {
  const Transform t = toWorld;
  for (int i = 0; i < n; ++i) {
    const Vec2f uv = EnvironmentMapView::dirToUV(t.inverseVector(Vec3f(d0[i], d1[i], d2[i])));
    us[i] = uv.x, vs[i] = uv.y;
  }
}

// EnvironmentMapView::lookupUV, its texels gathered. The members it reads are passed apart, the
// texels as restrict, so that the arrays written cannot alias them; its two flags are constants
// of each instance, since GCC vectorises neither a select on a flag nor both of its branches.
template <bool Bilinear, bool RowsFromPoles>
ENVGI_LANES void mapLookups(int n, const float* __restrict texels, int width, int height, float scale,
                            const int* __restrict at, const float* __restrict us, const float* __restrict vs,
                            float* __restrict r, float* __restrict g, float* __restrict b) {
  for (int j = 0; j < n; ++j) {
    const Color c = EnvironmentMapView::lookupIn<uint32_t>(texels, width, height, RowsFromPoles, scale, Bilinear,
                                                           Vec2f(us[at[j]], vs[at[j]]));
    r[j] = c.x, g[j] = c.y, b[j] = c.z;
  }
}

// EnvironmentMapView::placeInPixel without insidePixel's last steps (warpInPixelIn's Settle),
// into ou, ov, opdf; redo marks the lanes whose point is not yet in its pixel, which
// placeInPixel itself then places. Its offsets in 32 bits, as mapLookups'. Flattened: GCC left
// the warp as a call, which no loop around it vectorises.
#if defined(__GNUC__) && !defined(__clang__)
__attribute__((flatten))
#endif
ENVGI_LANES void placeInPixels(int n, const float* __restrict texels, const uint32_t* __restrict warpBits, int width,
                               int height, const float* __restrict us, const float* __restrict vs,
                               const float* __restrict pdfs, float* __restrict ou, float* __restrict ov,
                               float* __restrict opdf, unsigned char* __restrict redo) {
  using View = EnvironmentMapView;
  for (int j = 0; j < n; ++j) {
    const View::PixelPoint p = View::pixelPointIn(width, height, Vec2f(us[j], vs[j]));
    float rel;
    const Vec2f w = View::warpInPixelIn<uint32_t, false>(texels, width, height, p, &rel);
    // Compared as a float: GCC turns the bit's comparison into a conversion to bool, which it
    // does not vectorise.
    const bool warp = float(View::warpBitIn<uint32_t>(warpBits, width, p)) > 0.5f;
    const bool settled = int(w.x * float(width)) == p.x && int(w.y * float(height)) == p.y;
    redo[j] = warp && !settled;
    ou[j] = warp ? w.x : us[j];
    ov[j] = warp ? w.y : vs[j];
    opdf[j] = warp ? pdfs[j] * rel : pdfs[j];
  }
}

// A two-sided BSDF's wo seen from the front (sampleInFrame's flip).
inline float frontZ(bool twoSided, float z) { return twoSided && z < 0.f ? -z : z; }

// Rough plastic's sample (detail::roughPlasticDisk, roughPlasticDirection and the rest) in
// steps, each a loop over the lanes. Where a direction falls among the coat's table nodes is
// kept in arrays (at, share) from one loop to the next (coatPlace). The material's members
// are read from a copy, which the arrays written cannot alias; it has its tables
// (samplesInLanes), which is said, so that the branches to the smooth coat's Fresnel terms go.
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
  const MicrofacetDistribution d{dist.alphaX, dist.alphaY, MicrofacetType::GGX};  // samplesInLanes': GGX
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
    // Written whatever the sides; the zeros below the surface are chosen when read (bsdfEvalOf):
    // chosen here, GCC made the table's gathers conditional, which it does not vectorise.
    above[i] = (wo.z > 0.f) & (wi.z > 0.f);
    fr[i] = f.x, fg[i] = f.y, fb[i] = f.z, pdf[i] = p;
  }
}

}  // namespace

void RoundLanes::resize(size_t n) {
  if (px.size() >= n) return;
  for (std::vector<float>* a :
       {&ux, &uy, &lx, &ly, &weight, &ox, &oy, &oz, &dx, &dy, &dz, &tMax, &u, &v, &lightU0, &lightU1, &bsdfU0, &bsdfU1,
        &red, &green, &blue, &drawU, &drawV, &drawPdf, &placedPdf, &woX, &woY, &woZ, &sampleU0, &sampleU1, &diskR,
        &diskAngle, &diskX, &diskY, &coatLobe, &wiX, &wiY, &wiZ, &weightR, &weightG, &weightB, &samplePdf, &frontZ,
        &fo, &coatShare, &frontZi, &coatShareI})
    a->resize(n);
  px.resize(n), py.resize(n), hash.resize(n), dims.resize(n), picked.resize(n), redo.resize(n), sampled.resize(n);
  coatAt.resize(n), coatAtI.resize(n);
}

void RoundLanes::make(const Camera& cam, const Sampler& first, int n) {
  resize(size_t(n));
  pixelHashes(n, px.data(), py.data(), uint64_t(cam.width), first.seed, hash.data());
  sobolDraws(n, hash.data(), 0, first.indexInPixel, first.block, first.blockSeed, ux.data(), uy.data());
  if (cam.hasLens()) sobolDraws(n, hash.data(), 2, first.indexInPixel, first.block, first.blockSeed, lx.data(), ly.data());
  // The other filters one lane at a time: a logarithm and a sine, or a table's search.
  if (cam.filter.type == FilterType::Box) {
    boxOffsets(n, ux.data(), uy.data(), weight.data());
  } else {
    for (int i = 0; i < n; ++i) {
      const FilterSample fs = sampleFilter(cam.filter, Vec2f(ux[i], uy[i]));
      ux[i] = fs.offset.x, uy[i] = fs.offset.y, weight[i] = fs.weight;
    }
  }
  const RayLanes out{ox.data(), oy.data(), oz.data(), dx.data(), dy.data(), dz.data(), tMax.data()};
  if (cam.hasLens() || cam.orthographic) {
    for (int i = 0; i < n; ++i)
      out.put(i, cam.generateRay(imageX(px.data(), ux.data(), i), imageX(py.data(), uy.data(), i),
                                 cam.hasLens() ? Vec2f(lx[i], ly[i]) : Vec2f(0.5f, 0.5f)));
  } else {
    pinholeRays(n, cam, px.data(), py.data(), ux.data(), uy.data(), out);
  }
}

void RoundLanes::drawPairs(const Sampler& first, int n, uint32_t lightAt, uint32_t bsdfAt) {
  sobolDrawsAt(n, hash.data(), dims.data(), lightAt, first.indexInPixel, first.block, first.blockSeed, lightU0.data(),
               lightU1.data());
  sobolDrawsAt(n, hash.data(), dims.data(), bsdfAt, first.indexInPixel, first.block, first.blockSeed, bsdfU0.data(),
               bsdfU1.data());
}

void RoundLanes::mapUV(const EnvironmentMapView& env, int n) {
  mapCoordinates(n, env.toWorld, dx.data(), dy.data(), dz.data(), u.data(), v.data());
}

void RoundLanes::mapRadiance(const EnvironmentMapView& env, int n) {
  if (env.fitsUnsignedIndex()) {
    auto lookups = !env.bilinear       ? mapLookups<false, false>
                   : env.rowsFromPoles ? mapLookups<true, true>
                                       : mapLookups<true, false>;
    lookups(n, env.texels, env.width, env.height, env.scale, picked.data(), u.data(), v.data(), red.data(),
            green.data(), blue.data());
    return;
  }
  for (int j = 0; j < n; ++j) {
    const Color c = env.lookupUV(uvOf(picked[j]));
    red[j] = c.x, green[j] = c.y, blue[j] = c.z;
  }
}

void RoundLanes::placeDraws(const EnvironmentMapView& env, int n) {
  // Placed into u, v and placedPdf (u and v are free once a round's escapes have taken theirs),
  // so that mapRadiance then looks the map up there.
  auto placeOne = [&](int j) {
    placedPdf[j] = drawPdf[j];
    const Vec2f uv = env.placeInPixel(Vec2f(drawU[j], drawV[j]), &placedPdf[j]);
    u[j] = uv.x, v[j] = uv.y;
  };
  const bool inLanes = env.warpBits && env.fitsUnsignedIndex();
  if (inLanes)
    placeInPixels(n, env.texels, env.warpBits, env.width, env.height, drawU.data(), drawV.data(), drawPdf.data(),
                  u.data(), v.data(), placedPdf.data(), redo.data());
  for (int j = 0; j < n; ++j)
    if (!inLanes || redo[j]) placeOne(j);
  for (int j = 0; j < n; ++j) picked[j] = j;
  mapRadiance(env, n);
}

void RoundLanes::sampleRoughPlastic(const Bsdf& b, int n) {
  const CoatNode coat = detail::roughCoat(b);
  const MicrofacetDistribution d = microfacet(b);
  // woZ keeps the given side; frontZ holds wo's z seen from the front. diskX holds the stretched
  // u.x until fromPolar's loop writes the disk points there.
  coatPlaces(n, woZ.data(), frontZ.data(), b.twoSided, coatAt.data(), coatShare.data());
  roughPlasticLobes(n, b, coat, coatAt.data(), coatShare.data(), sampleU0.data(), fo.data(), diskX.data(),
                    coatLobe.data());
  roughPlasticDisks(n, diskX.data(), sampleU1.data(), coatLobe.data(), diskR.data(), diskAngle.data());
  for (int i = 0; i < n; ++i) {
    const Vec2f p = fromPolar({diskR[i], diskAngle[i]});
    diskX[i] = p.x, diskY[i] = p.y;
  }
  roughPlasticDirections(n, d, woX.data(), woY.data(), frontZ.data(), diskX.data(), diskY.data(), coatLobe.data(),
                         wiX.data(), wiY.data(), wiZ.data(), coatAt.data(), coatShare.data());
  auto values = b.nonlinear ? roughPlasticValues<true> : roughPlasticValues<false>;
  values(n, b, coat, d, woX.data(), woY.data(), frontZ.data(), fo.data(), woZ.data(), coatAt.data(), coatShare.data(),
         wiX.data(), wiY.data(), wiZ.data(), weightR.data(), weightG.data(), weightB.data(), samplePdf.data(),
         sampled.data());
}

void RoundLanes::evalRoughPlastic(const Bsdf& b, int n) {
  evalPlaces(n, woZ.data(), wiZ.data(), b.twoSided, frontZ.data(), frontZi.data(), coatAt.data(), coatShare.data(),
             coatAtI.data(), coatShareI.data());
  auto evals = b.nonlinear ? roughPlasticEvals<true> : roughPlasticEvals<false>;
  evals(n, b, detail::roughCoat(b), microfacet(b), woX.data(), woY.data(), frontZ.data(), wiX.data(), wiY.data(),
        frontZi.data(), coatAt.data(), coatShare.data(), coatAtI.data(), coatShareI.data(), weightR.data(),
        weightG.data(), weightB.data(), samplePdf.data(), sampled.data());
}

}  // namespace envgi
