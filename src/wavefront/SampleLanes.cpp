#include "wavefront/SampleLanes.h"

#include "core/Lanes.h"

namespace envgi {

namespace {

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

}  // namespace

void SampleLanes::resize(size_t n) {
  if (px.size() >= n) return;
  for (std::vector<float>* a :
       {&ux, &uy, &lx, &ly, &weight, &ox, &oy, &oz, &dx, &dy, &dz, &tMax, &lightU0, &lightU1, &bsdfU0, &bsdfU1})
    a->resize(n);
  px.resize(n), py.resize(n), hash.resize(n), dims.resize(n);
}

void SampleLanes::make(const Camera& cam, const Sampler& first, int n) {
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

void SampleLanes::drawPairs(const Sampler& first, int n, uint32_t lightAt, uint32_t bsdfAt) {
  sobolDrawsAt(n, hash.data(), dims.data(), lightAt, first.indexInPixel, first.block, first.blockSeed, lightU0.data(),
               lightU1.data());
  sobolDrawsAt(n, hash.data(), dims.data(), bsdfAt, first.indexInPixel, first.block, first.blockSeed, bsdfU0.data(),
               bsdfU1.data());
}

}  // namespace envgi
