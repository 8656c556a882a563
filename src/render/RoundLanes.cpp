#include "render/RoundLanes.h"

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

}  // namespace

void RoundLanes::resize(size_t n) {
  if (px.size() >= n) return;
  for (std::vector<float>* a : {&ux, &uy, &lx, &ly, &weight, &ox, &oy, &oz, &dx, &dy, &dz, &tMax, &u, &v, &lightU0,
                                &lightU1, &bsdfU0, &bsdfU1, &red, &green, &blue, &drawU, &drawV, &drawPdf, &placedPdf})
    a->resize(n);
  px.resize(n), py.resize(n), hash.resize(n), dims.resize(n), picked.resize(n), redo.resize(n);
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

void RoundLanes::drawAhead(const Sampler& first, int n, uint32_t lightAt, uint32_t bsdfAt) {
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

}  // namespace envgi
