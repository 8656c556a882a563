// A tile round's samples made lane by lane (core/Lanes.h): the camera round's samples (the
// pixels' hashes, their Sobol draws, the filter's offsets, the rays), and the hits' pairs of
// Sobol draws at bounceLayout's offsets. One sample at a time, the camera's share was a third of
// the time outside Embree on the buddha bench. Each lane calls the function the one-sample
// path calls (sobolDraw2D, Camera::pinholeRay), so rays and draws are the same to the bit.
#pragma once

#include <cstdint>
#include <vector>

#include "sampling/Sampler.h"
#include "scene/Camera.h"

namespace envgi {

struct SampleLanes {
  // make: in, each lane's pixel; out, its hash (Sampler::pixelHash), the filter's weight, the ray.
  std::vector<int> px, py;
  std::vector<uint64_t> hash;
  std::vector<float> ux, uy, lx, ly, weight;
  std::vector<float> ox, oy, oz, dx, dy, dz, tMax;
  // drawPairs: in, each lane's sampler (its pixel's hash, its position); out, two pairs of it.
  std::vector<uint32_t> dims;
  std::vector<float> lightU0, lightU1, bsdfU0, bsdfU1;

  void resize(size_t n);

  // Whether a round of this sequence can be made here: Sobol's draws are pure functions of the
  // pixel's hash; the other samplers step a generator, one sample at a time.
  static bool handles(const Sampler& first) { return first.type == SamplerType::Sobol; }
  // The dimensions a camera sample draws (sampleCameraRay): the filter's pair, and the lens's.
  static uint32_t dimensions(const Camera& cam) { return cam.hasLens() ? 4u : 2u; }

  // Lanes [0, n) (px, py set): what Sampler::startPixel and sampleCameraRay give for sample
  // first.index of each lane's pixel, first being sequenceSampler's with setIndex done.
  void make(const Camera& cam, const Sampler& first, int n);
  Ray rayOf(int i) const { return Ray{Vec3f(ox[i], oy[i], oz[i]), Vec3f(dx[i], dy[i], dz[i]), tMax[i]}; }

  // A round's hits: lane j's sampler, and the two 2D draws at lightAt and bsdfAt dimensions past
  // its position, for sample first.index (first as in make()).
  void setSampler(int j, const Sampler& smp) { hash[j] = smp.pixelHash, dims[j] = smp.dim; }
  void drawPairs(const Sampler& first, int n, uint32_t lightAt, uint32_t bsdfAt);
  Vec2f lightDraw(int j) const { return {lightU0[j], lightU1[j]}; }
  Vec2f bsdfDraw(int j) const { return {bsdfU0[j], bsdfU1[j]}; }
};

}  // namespace envgi
