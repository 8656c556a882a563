// The BSDF work of a round's hits on rough plastics (RoundLanes::samplesInLanes), done in vector
// lanes a material at a time: the BSDF samples, and the values at the product draws' directions.
// pathShade then takes them (drawBsdfSample, prepareLd).
#pragma once

#include "wavefront/TileQueues.h"

namespace envgi {

// Lanes over the hits q->sampling[0, count), a material at a time: put(n, k) sets lane n from
// hit k, run(material, n) runs lanes [0, n), take(j, k) reads lane j back into hit k.
template <class Put, class Run, class Take>
inline void byMaterial(TileQueues* q, int count, Put put, Run run, Take take) {
  int left = count;
  while (left > 0) {
    const int material = q->ahead[q->sampling[0]].si.bsdf;
    int n = 0, rest = 0;
    for (int i = 0; i < left; ++i) {
      const int k = q->sampling[i];
      if (q->ahead[k].si.bsdf != material) {
        q->sampling[rest++] = k;
        continue;
      }
      q->picking[n] = k;
      put(n++, k);
    }
    run(material, n);
    for (int j = 0; j < n; ++j) take(j, q->picking[j]);
    left = rest;
  }
}

// What pathShade's woLocal is for hit k (its interaction found ahead).
inline Vec3f aheadWo(const TileQueues* q, int k) { return q->ahead[k].si.shading.toLocal(-q->state[k].ray.d); }

// The BSDF samples of hits [0, hits) of q->hits into each hit's ahead.bs, from the pairs drawn
// ahead (ahead.ub); a path that ends before its BSDF sample is left out.
inline void sampleBsdfsInLanes(const SceneView& sc, const PathParams& pp, TileQueues* q, int hits) {
  if (!pp.bsdfSample) return;
  int count = 0;
  for (int j = 0; j < hits; ++j) {
    const int k = q->hits[j];
    if (!(pp.maxDepth >= 0 && q->state[k].depth >= pp.maxDepth) &&
        RoundLanes::samplesInLanes(sc.bsdfs[q->ahead[k].si.bsdf]))
      q->sampling[count++] = k;
  }
  RoundLanes& lanes = q->lanes;
  byMaterial(
      q, count, [&](int n, int k) { lanes.setBsdfDraw(n, aheadWo(q, k), q->ahead[k].ub); },
      [&](int material, int n) { lanes.sampleRoughPlastic(sc.bsdfs[material], n); },
      [&](int j, int k) {
        BsdfSampleAhead& s = q->ahead[k].bs;
        s.ok = lanes.bsdfSampleOf(j, &s.s);
        s.made = true;
      });
}

// The same BSDFs evaluated for their light samples' directions, where the light sample is a
// product draw placed ahead (ahead.product): the draw's world direction is worked out here,
// which EnvironmentMapView::sample then takes, and prepareLd takes the value and density
// (BsdfEvalAhead) for that direction. Hits [0, draws) of q->productDraws; a hit with a blend's
// partner is left out (prepareLd evaluates the two together).
inline void evalBsdfsInLanes(const SceneView& sc, TileQueues* q, int draws) {
  int count = 0;
  for (int i = 0; i < draws; ++i) {
    const int k = q->productDraws[i];
    const ShadeAhead& a = q->ahead[k];
    if (a.product.drawn && a.product.placed && a.si.partner < 0 && RoundLanes::samplesInLanes(sc.bsdfs[a.si.bsdf]))
      q->sampling[count++] = k;
  }
  RoundLanes& lanes = q->lanes;
  const EnvironmentMapView& env = sc.env;
  byMaterial(
      q, count,
      [&](int n, int k) {
        ProductDraw& d = q->ahead[k].product;
        d.dir = env.fromLocal(EnvironmentMapView::uvToDir(d.uv));  // sample()'s, for the placed draw
        d.directed = true;
        lanes.setBsdfEval(n, aheadWo(q, k), q->ahead[k].si.shading.toLocal(d.dir));  // prepareLd's wiLocal
      },
      [&](int material, int n) { lanes.evalRoughPlastic(sc.bsdfs[material], n); },
      [&](int j, int k) { q->ahead[k].ev = lanes.bsdfEvalOf(j); });
}

}  // namespace envgi
