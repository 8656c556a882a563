// The lanes of a tile's round (wavefront/TileWavefront.h): work done a step at a time across the
// round's paths, each step a loop over plain arrays that the compiler vectorises. The camera
// round's samples (the pixels' hashes, their Sobol draws, the filter's offsets, the rays), and
// in every round, where the rays that escaped meet the map. One sample at a time, the camera's
// share was a third of the time outside Embree on the buddha bench.
// Each step calls the function the one-sample path calls (sobolDraw2D, Camera::pinholeRay,
// EnvironmentMapView::dirToUV), so rays and draws are the same to the bit: a lane does each
// float operation as the scalar instruction does (no contraction into FMA: the AVX2 clones are
// built without it).
#pragma once

#include <cstdint>
#include <vector>

#include "envmap/EnvironmentMapView.h"
#include "materials/Bsdf.h"
#include "sampling/Sampler.h"
#include "scene/Camera.h"

namespace envgi {

// A BSDF's value f and density pdf for the direction wi, as bsdfEvalPdf gives them.
struct LaneBsdfValue {
  Vec3f wi;
  Color f;
  float pdf = 0.f;
};

struct RoundLanes {
  // In: each lane's pixel. Out: its hash (Sampler::pixelHash), the filter's weight, the ray.
  std::vector<int> px, py;
  std::vector<uint64_t> hash;
  std::vector<float> ux, uy, lx, ly, weight;
  std::vector<float> ox, oy, oz, dx, dy, dz, tMax;
  std::vector<float> u, v;  // mapUV: where each direction (dx, dy, dz) meets the map
  std::vector<int> picked;            // mapRadiance: in, the lanes it looks up
  std::vector<float> red, green, blue;  // and out, the map's radiance there, by place in picked
  // placeDraws: in, the round's product draws (CosineProductView::descentEnd's uv and pdfUV);
  // out, the same placed inside their pixels (u, v, placedPdf), with the radiance there in red,
  // green, blue.
  std::vector<float> drawU, drawV, drawPdf, placedPdf;
  std::vector<unsigned char> redo;
  // drawPairs: in, each lane's sampler (its pixel's hash, its position); out, two pairs of it.
  std::vector<uint32_t> dims;
  std::vector<float> lightU0, lightU1, bsdfU0, bsdfU1;
  // sampleRoughPlastic: in, each lane's wo in its shading frame and its BSDF pair; between its
  // steps, wo's z seen from the front, its coat reflectance, the disk points (polar, then
  // Cartesian), the lobe (1: the coat) and a direction's place among the coat's nodes; out, the
  // sample.
  std::vector<float> woX, woY, woZ, sampleU0, sampleU1;
  std::vector<float> frontZ, fo, diskR, diskAngle, diskX, diskY, coatLobe, coatShare;
  std::vector<int> coatAt;
  // evalRoughPlastic: in, wo (woX, woY, woZ) and wi (wiX, wiY, wiZ); between its steps, wi's z
  // seen from the front and its place among the coat's nodes; out, the value (weightR, weightG,
  // weightB) and the density (samplePdf), which count where both directions are above the
  // surface (sampled).
  std::vector<float> frontZi, coatShareI;
  std::vector<int> coatAtI;
  std::vector<float> wiX, wiY, wiZ, weightR, weightG, weightB, samplePdf;
  std::vector<unsigned char> sampled;

  void resize(size_t n);

  // Whether a round of this sequence can be made here: Sobol's draws are pure functions of the
  // pixel's hash; the other samplers step a generator, one sample at a time.
  static bool handles(const Sampler& first) { return first.type == SamplerType::Sobol; }
  // The dimensions a camera sample draws (sampleCameraRay): the filter's pair, and the lens's.
  static uint32_t dimensions(const Camera& cam) { return cam.hasLens() ? 4u : 2u; }

  // Lanes [0, n) (px, py set): what Sampler::startPixel and sampleCameraRay give for sample
  // first.index of each lane's pixel, first being sequenceSampler's with setIndex done.
  void make(const Camera& cam, const Sampler& first, int n);
  void setDirection(int i, Vec3f d) { dx[i] = d.x, dy[i] = d.y, dz[i] = d.z; }
  Ray rayOf(int i) const { return Ray{Vec3f(ox[i], oy[i], oz[i]), Vec3f(dx[i], dy[i], dz[i]), tMax[i]}; }

  // A round's hits: lane j's sampler, and the two 2D draws at lightAt and bsdfAt dimensions past
  // its position, for sample first.index (first as in make()).
  void setSampler(int j, const Sampler& smp) { hash[j] = smp.pixelHash, dims[j] = smp.dim; }
  void drawPairs(const Sampler& first, int n, uint32_t lightAt, uint32_t bsdfAt);
  Vec2f lightDraw(int j) const { return {lightU0[j], lightU1[j]}; }
  Vec2f bsdfDraw(int j) const { return {bsdfU0[j], bsdfU1[j]}; }

  // Lanes [0, n): where each direction (dx, dy, dz) meets the map, as EnvironmentMapView::eval
  // finds it. The camera round's rays, or a round's escaped rays gathered there.
  void mapUV(const EnvironmentMapView& env, int n);
  Vec2f uvOf(int i) const { return {u[i], v[i]}; }
  // Places [0, n) of picked (lanes whose u and v mapUV found): the map's radiance at each, as
  // EnvironmentMapView::lookupUV gives it there.
  void mapRadiance(const EnvironmentMapView& env, int n);
  Color radianceOf(int j) const { return Color(red[j], green[j], blue[j]); }
  // Lanes [0, n) of drawU, drawV, drawPdf: each draw placed inside its pixel as
  // EnvironmentMapView::placeInPixel places it, and the map's radiance there (lookupUV's).
  void placeDraws(const EnvironmentMapView& env, int n);
  void setDraw(int j, Vec2f uv, float pdfUV) { drawU[j] = uv.x, drawV[j] = uv.y, drawPdf[j] = pdfUV; }
  // Lane j's draw as placeDraws left it, for ProductDraw: placed, with its radiance.
  void placedDraw(int j, Vec2f* uv, float* pdfUV, Color* radiance) const {
    *uv = uvOf(j), *pdfUV = placedPdf[j], *radiance = radianceOf(j);
  }

  // Whether sampleRoughPlastic takes this material: a rough plastic of GGX, isotropic, with its
  // coat's tables and no texture (nor a normal or bump map). The example scenes' glossy BSDF;
  // others are sampled one at a time, as before.
  static bool samplesInLanes(const Bsdf& b) {
    return b.type == BsdfType::RoughPlastic && b.distribution == MicrofacetType::GGX && !bsdfIsAnisotropic(b) &&
           !bsdfHasTexture(b) && !bsdfIsBlend(b) && b.coatNodes > 0;
  }
  void setBsdfDraw(int j, Vec3f wo, Vec2f u) { woX[j] = wo.x, woY[j] = wo.y, woZ[j] = wo.z, sampleU0[j] = u.x, sampleU1[j] = u.y; }
  // Lanes [0, n), all of material b (samplesInLanes): what bsdfSample(b, wo, 0, u, s, true)
  // gives for each, to the bit, with libm's sine and cosine taken one lane at a time.
  void sampleRoughPlastic(const Bsdf& b, int n);
  // Lanes [0, n), all of material b (samplesInLanes), wo and wi given (setBsdfEval): what
  // bsdfEvalPdf(b, wo, wi, &pdf) gives for each, to the bit.
  void setBsdfEval(int j, Vec3f wo, Vec3f wi) {
    woX[j] = wo.x, woY[j] = wo.y, woZ[j] = wo.z, wiX[j] = wi.x, wiY[j] = wi.y, wiZ[j] = wi.z;
  }
  void evalRoughPlastic(const Bsdf& b, int n);
  LaneBsdfValue bsdfEvalOf(int j) const {
    LaneBsdfValue e;
    e.wi = Vec3f(wiX[j], wiY[j], wiZ[j]);
    e.f = sampled[j] ? Color(weightR[j], weightG[j], weightB[j]) : Color(0.f);
    e.pdf = sampled[j] ? samplePdf[j] : 0.f;
    return e;
  }
  // Lane j's answer: false where bsdfSample gives no sample, else the sample in *s.
  bool bsdfSampleOf(int j, BsdfSample* s) const {
    s->wi = Vec3f(wiX[j], wiY[j], wiZ[j]);
    s->weight = Color(weightR[j], weightG[j], weightB[j]);
    s->pdf = samplePdf[j];
    s->delta = false;
    return sampled[j] != 0;
  }
};

}  // namespace envgi
