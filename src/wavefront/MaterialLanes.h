// The BSDF work of a round's hits on the materials with lanes (RoughPlasticLanes,
// RoughConductorLanes), done in vector lanes a material at a time: the BSDF samples, and the
// values at the product draws' directions, which PreparedParts then hands to pathShade.
#pragma once

#include "wavefront/HostLanes.h"
#include "wavefront/WaveQueues.h"

namespace envgi {

// Lanes over the hits q->sampling[0, count), a material at a time: put(n, k) sets lane n from
// hit k, run(material, n) runs lanes [0, n), take(j, k) reads lane j back into hit k.
template <class Put, class Run, class Take>
inline void byMaterial(HostLanes* q, int count, Put put, Run run, Take take) {
  int left = count;
  while (left > 0) {
    const int material = q->prepared[q->sampling[0]].si.bsdf;
    int n = 0, rest = 0;
    for (int i = 0; i < left; ++i) {
      const int k = q->sampling[i];
      if (q->prepared[k].si.bsdf != material) {
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

// What pathShade's woLocal is for hit k (its interaction prepared).
inline Vec3f preparedWo(const WaveQueues& w, const HostLanes* q, int k) {
  return q->prepared[k].si.shading.toLocal(-w.state[k].ray.d);
}

// The BSDF samples of hits[0, n) on materials of one kind (Lanes::takes), into
// each hit's prepared sample, from the pairs drawn for the round (prepared.ub); a path that ends
// before its BSDF sample is left out.
template <class Lanes>
void sampleKindInLanes(const SceneView& sc, const PathParams& pp, const WaveQueues& w, HostLanes* q, const int* hits,
                       int n, Lanes& lanes) {
  int count = 0;
  for (int j = 0; j < n; ++j) {
    const int k = hits[j];
    if (!(pp.maxDepth >= 0 && w.state[k].depth >= pp.maxDepth) && Lanes::takes(sc.bsdfs[q->prepared[k].si.bsdf]))
      q->sampling[count++] = k;
  }
  byMaterial(
      q, count, [&](int n, int k) { lanes.setSample(n, preparedWo(w, q, k), q->prepared[k].ub); },
      [&](int material, int n) { lanes.sample(sc.bsdfs[material], n); },
      [&](int j, int k) {
        PreparedHit& p = q->prepared[k];
        p.sampleTaken = lanes.sampleOf(j, &p.sample);
        p.sampled = true;
      });
}

// The same BSDFs evaluated for their light samples' directions, where the light sample is a
// product draw placed in lanes (prepared.product, with its direction): prepareLd's wiLocal.
// Hits [0, draws) of q->productDraws; a hit with a blend's partner is left out (the two are
// evaluated together).
template <class Lanes>
void evalKindInLanes(const SceneView& sc, const WaveQueues& w, HostLanes* q, int draws, Lanes& lanes) {
  int count = 0;
  for (int i = 0; i < draws; ++i) {
    const int k = q->productDraws[i];
    const PreparedHit& p = q->prepared[k];
    if (p.product.drawn && p.product.placed && p.si.partner < 0 && Lanes::takes(sc.bsdfs[p.si.bsdf]))
      q->sampling[count++] = k;
  }
  byMaterial(
      q, count,
      [&](int n, int k) {
        const PreparedHit& p = q->prepared[k];
        lanes.setEval(n, preparedWo(w, q, k), p.si.shading.toLocal(p.product.dir));
      },
      [&](int material, int n) { lanes.eval(sc.bsdfs[material], n); },
      [&](int j, int k) {
        q->prepared[k].value = lanes.evalOf(j);
        q->prepared[k].valued = true;
      });
}

// Each material kind with lanes of its own, its hits queued apart: rough plastics, then rough
// conductors. Other materials are sampled and evaluated one path at a time, where pathShade asks.
inline void sampleBsdfsInLanes(const SceneView& sc, const PathParams& pp, const WaveQueues& w, HostLanes* q,
                               const int* hits, int n) {
  if (!pp.bsdfSample) return;
  sampleKindInLanes(sc, pp, w, q, hits, n, q->roughPlastic);
  sampleKindInLanes(sc, pp, w, q, hits, n, q->roughConductor);
}
inline void evalBsdfsInLanes(const SceneView& sc, const WaveQueues& w, HostLanes* q, int draws) {
  evalKindInLanes(sc, w, q, draws, q->roughPlastic);
  evalKindInLanes(sc, w, q, draws, q->roughConductor);
}

}  // namespace envgi
