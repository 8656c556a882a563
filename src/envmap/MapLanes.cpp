#include "envmap/MapLanes.h"

#include "core/Lanes.h"

namespace envgi {

namespace {

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

void MapLanes::resize(size_t n) {
  if (u.size() >= n) return;
  for (std::vector<float>* a : {&dx, &dy, &dz, &u, &v, &red, &green, &blue, &drawU, &drawV, &drawPdf, &placedU, &placedV,
                                &placedPdf})
    a->resize(n);
  picked.resize(n), redo.resize(n);
}

void MapLanes::findUV(const EnvironmentMapView& env, int n, const float* x, const float* y, const float* z) {
  mapCoordinates(n, env.toWorld, x, y, z, u.data(), v.data());
}

void MapLanes::lookUp(const EnvironmentMapView& env, int n) { lookUpAt(env, n, u.data(), v.data()); }

void MapLanes::lookUpAt(const EnvironmentMapView& env, int n, const float* us, const float* vs) {
  if (env.fitsUnsignedIndex()) {
    auto lookups = !env.bilinear       ? mapLookups<false, false>
                   : env.rowsFromPoles ? mapLookups<true, true>
                                       : mapLookups<true, false>;
    lookups(n, env.texels, env.width, env.height, env.scale, picked.data(), us, vs, red.data(), green.data(),
            blue.data());
    return;
  }
  for (int j = 0; j < n; ++j) {
    const Color c = env.lookupUV(Vec2f(us[picked[j]], vs[picked[j]]));
    red[j] = c.x, green[j] = c.y, blue[j] = c.z;
  }
}

void MapLanes::placeDraws(const EnvironmentMapView& env, int n) {
  const bool inLanes = env.warpBits && env.fitsUnsignedIndex();
  if (inLanes)
    placeInPixels(n, env.texels, env.warpBits, env.width, env.height, drawU.data(), drawV.data(), drawPdf.data(),
                  placedU.data(), placedV.data(), placedPdf.data(), redo.data());
  for (int j = 0; j < n; ++j) {
    if (inLanes && !redo[j]) continue;
    placedPdf[j] = drawPdf[j];
    const Vec2f uv = env.placeInPixel(Vec2f(drawU[j], drawV[j]), &placedPdf[j]);
    placedU[j] = uv.x, placedV[j] = uv.y;
  }
  for (int j = 0; j < n; ++j) picked[j] = j;
  lookUpAt(env, n, placedU.data(), placedV.data());
}

}  // namespace envgi
