// The CPU's wavefront over one tile: samples [s0, s1) of the tile [x0, x1) x [y0, y1), sample s
// of every pixel together, each round running the stages of TileStages.h over all live paths.
// The camera rays go to the tracer together, for packets; each round's bounce and shadow rays
// as streams. Each pixel adds its samples in renderPixel's order, so the film's sums are the
// same to the bit where the tracer's packets give one-ray hits to the bit (the BVH's loop does;
// Embree's packets round t in their own way).
#pragma once

#include "wavefront/TileStages.h"

namespace envgi {

template <class Integrator>
void renderTileWavefront(const Camera& cam, const SampleSequence& seq, const Integrator& integ, int x0, int y0, int x1,
                         int y1, int s0, int s1, FilmView film, TileQueues* q, PixelCounters* counters) {
  const int tw = x1 - x0, n = tw * (y1 - y0);
  q->resize(size_t(n));
  for (int k = 0; k < n; ++k) q->acc[k] = Color(0.f), q->accSq[k] = 0.0, q->accW[k] = 0.f;
  for (int s = s0; s < s1; ++s) {
    Sampler first = sequenceSampler(seq);
    first.setIndex(uint32_t(s));
    const TileRound<Integrator> r{cam, integ, film, q, counters, x0, y0, x1, y1, first, SampleLanes::handles(first)};
    int live = startCameraSamples(r);
    // Made in lanes, the camera round is traced with them: every path left is a hit.
    const bool laneRound = r.inLanes && live > 0;
    if (laneRound) live = traceCameraLanes(r, live);
    for (bool cameraRays = true; live > 0; cameraRays = false) {
      if (!(cameraRays && laneRound)) traceClosest(r, live, cameraRays);
      prefetchHits(r, live);
      meetMap(r, live, cameraRays);
      walkProductDraws(r, prepareHits(r, live));
      traceShadowRays(r, shadeRound(r, live));
      live = resolveRound(r, live);
    }
  }
  for (int k = 0; k < n; ++k) {
    const size_t pixel = size_t(y0 + k / tw) * size_t(cam.width) + size_t(x0 + k % tw);
    if (!film.takesSamples(pixel)) continue;
    film.sum[pixel] += q->acc[k];
    if (film.sumSqLum) film.sumSqLum[pixel] += q->accSq[k];
    if (film.weightSum) film.weightSum[pixel] += q->accW[k];
  }
}

}  // namespace envgi
