// The wave stages' batch forms on the CPU (HostStageLaunch.h runs a stage through its batch form
// where it has one): a stage's work for its whole queue at once, so that the tracer takes the
// queue's rays as packets or a stream, lanes make the camera samples, the pairs of draws, the
// map's lookups and the BSDF samples of the materials with lanes (MaterialLanes.h), and the
// product draws' dependent loads overlap across the queue. Each leaves the slots and queues as
// the stage's function of one index would, to the bit; the lanes' room is the thread's HostLanes.
// A wave a tile keeps the BVH, then the map's tables, in cache through each stage (renderPixel
// took 4-8% longer on the buddha bench).
#pragma once

#include "wavefront/MaterialLanes.h"
#include "wavefront/WaveStages.h"

namespace envgi {

// Camera samples in lanes (SampleLanes::make), where the sampler's draws are pure functions of
// the pixel (Sobol) and the wave holds one sample of its pixels; else one at a time.
template <class I>
void runOnHost(const CameraStage<I>& s, int n, HostLanes* h) {
  const WaveContext<I>& c = s.c;
  const uint64_t npix = c.region.pixels(), sample = s.base / npix;
  h->first = sequenceSampler(c.seq);
  h->first.setIndex(uint32_t(s.s0 + int(sample)));
  h->inLanes = SampleLanes::handles(h->first) && (s.base + uint64_t(n) - 1) / npix == sample;
  if (!h->inLanes) {
    for (int i = 0; i < n; ++i) s(i);
    return;
  }
  SampleLanes& lanes = h->lanes;
  const int k0 = int(s.base % npix);
  int count = 0;
  for (int i = 0; i < n; ++i) {
    int dx, dy;
    c.region.at(k0 + i, &dx, &dy);
    if (!c.film.takesSamples(c.region.filmPixel(dx, dy, c.cam.width))) continue;
    lanes.px[count] = c.region.x0 + dx, lanes.py[count] = c.region.y0 + dy;
    h->laneSlot[count++] = i;
  }
  lanes.make(c.cam, h->first, count);
  const uint32_t dims = SampleLanes::dimensions(c.cam);
  for (int j = 0; j < count; ++j) {
    Sampler smp = h->first;
    smp.startPixelAt(lanes.hash[j], dims);
    s.start(h->laneSlot[j], lanes.rayOf(j), smp, lanes.weight[j], lanes.px[j] - c.region.x0,
            lanes.py[j] - c.region.y0);
  }
}

// The queue's rays traced together: the camera's as coherent packets (in the region's 4 x 4
// blocks), the bounces' as one stream. Then the hit triangles' indices and vertices are asked
// for across the queue before it is shaded, so that interaction()'s misses overlap.
template <class I>
void runOnHost(const ClosestHitStage<I>& s, int n, HostLanes* h) {
  const WaveQueues& q = s.c.q;
  const int* slots = q.rayQueue(s.parity);
  auto rayOf = [&](int i) -> const Ray& { return q.state[slots[i]].ray; };
  auto keep = [&](int i, bool found, const Hit& hit) {
    h->found[slots[i]] = found;
    if (found) q.hit[slots[i]] = hit;
  };
  if (s.cameraRound) s.c.integ.tracer.intersectCoherent(n, rayOf, keep);
  else s.c.integ.tracer.intersectMany(n, rayOf, keep);
  const SceneView& sc = *s.c.integ.scene;
  for (int i = 0; i < n; ++i)
    if (h->found[slots[i]]) sc.prefetchTriangle(q.hit[slots[i]]);
  for (int i = 0; i < n; ++i)
    if (h->found[slots[i]]) sc.prefetchVertices(q.hit[slots[i]]);
  for (int i = 0; i < n; ++i) s.queue(slots[i], h->found[slots[i]] != 0);
}

// What pathAddEscape will read from the map for a path whose ray escaped and meets it at uv,
// prefetched where it reads the map's density (past a non-delta bounce).
inline void prefetchEscape(const SceneView& sc, const PathState& st, const PathParams& pp, Vec2f uv) {
  if (!st.prevDelta && envSeenByBsdfSampling(pp.envStrategy, false))
    sc.env.prefetchEvalWithPdf(pp.envStrategy, uv, st.prevAxis);
}

// The escaped rays meet the map in lanes (MapLanes::findUV); the camera's rays look up its
// radiance there in lanes too, the later rounds' prefetch what their MIS weights read.
template <class I>
void runOnHost(const EscapeStage<I>& s, int n, HostLanes* h) {
  const SceneView& sc = *s.c.integ.scene;
  if (!sc.hasEnvironment) {
    for (int i = 0; i < n; ++i) s(i);
    return;
  }
  const WaveQueues& q = s.c.q;
  const PathParams pp = s.c.integ.shadedPath();
  for (int j = 0; j < n; ++j) h->map.setDirection(j, q.state[q.escaped[j]].ray.d);
  h->map.findUV(sc.env, n);
  if (s.cameraRound) {
    for (int j = 0; j < n; ++j) h->map.picked[j] = j;
    h->map.lookUp(sc.env, n);
  } else {
    for (int j = 0; j < n; ++j) prefetchEscape(sc, q.state[q.escaped[j]], pp, h->map.uvOf(j));
  }
  for (int j = 0; j < n; ++j) {
    const Color radiance = s.cameraRound ? h->map.radianceOf(j) : Color(0.f);
    s.escape(q.escaped[j], FoundEscapeParts{sc.env, h->map.uvOf(j), s.cameraRound ? &radiance : nullptr});
  }
}

// A hit's parts before it is shaded: its interaction and, where the path goes on to next-event
// estimation, its light pair (uL where inLanes, else the sampler's, from a copy of it). Where
// that light sample is a product draw, its descent begins in *d, and it returns true.
inline bool prepareHit(const SceneView& sc, const PathState& st, const Hit& h, const Sampler& smp,
                       const PathParams& pp, bool inLanes, Vec2f uL, PreparedHit* p, ProductDescent* d) {
  p->si = sc.interaction(st.ray, h);
  p->product.ended = p->product.placed = false;
  p->sampled = p->valued = false;
  p->lightDrawn = pp.lightSample && !(pp.maxDepth >= 0 && st.depth >= pp.maxDepth);
  if (!p->lightDrawn) return false;
  if (inLanes) {
    p->uL = uL;
  } else {
    Sampler peek = smp;
    p->uL = drawLight(sc, peek).uL;
  }
  // The material's own entry, untextured: its type is all that is asked of it here.
  const Bsdf& bsdf = sc.bsdfs[p->si.bsdf];
  Vec2f u = p->uL;
  if (!sc.hasEnvironment || bsdfIsDelta(bsdf) || !lightDrawPicksMap(sc, pp.envStrategy, &u)) return false;
  const Vec3f axis = envSamplingAxis(p->si, -st.ray.d, bsdf);
  if (sc.env.strategyFor(pp.envStrategy, axis) != EnvStrategy::Product) return false;
  sc.env.product.descend0(u, sc.env.toLocalUnnormalized(axis), d);
  return d->k >= 0;
}

// The product draws of h->productDraws[0, draws): their dependent loads a level at a time
// across them (ProductDescent), then the texels of the pixels they land in, then each draw's
// end. In lanes, each draw is then placed inside its pixel, the map looked up there, and the
// materials with lanes evaluated in its direction.
inline void walkProductDraws(const SceneView& sc, const WaveQueues& q, HostLanes* h, int draws) {
  const EnvironmentMapView& env = sc.env;
  const int* d = h->productDraws.data();
  for (int i = 0; i < draws; ++i) env.product.descend1(&h->descent[d[i]]);
  for (int i = 0; i < draws; ++i) env.product.descend2(&h->descent[d[i]]);
  for (int i = 0; i < draws; ++i) env.product.descend3(&h->descent[d[i]]);
  for (int i = 0; i < draws; ++i) {
    int px, py;
    if (env.product.descendToPixel(&h->descent[d[i]], &px, &py)) env.prefetchPixel(px, py);
  }
  int placing = 0;
  for (int i = 0; i < draws; ++i) {
    const ProductDescent& a = h->descent[d[i]];
    DescendedDraw& p = h->prepared[d[i]].product;
    p.ended = true;
    p.u = a.u, p.nLocal = a.nLocal;
    p.drawn = env.product.descentEnd(a, &p.uv, &p.pdfUV);
    if (h->inLanes && p.drawn) h->map.setDraw(placing++, p.uv, p.pdfUV);
  }
  if (placing == 0) return;
  h->map.placeDraws(env, placing);
  for (int i = 0, j = 0; i < draws; ++i) {
    DescendedDraw& p = h->prepared[d[i]].product;
    if (!p.drawn) continue;
    h->map.placedDraw(j++, &p.uv, &p.pdfUV, &p.radiance);
    p.dir = env.fromLocal(EnvironmentMapView::uvToDir(p.uv));  // EnvironmentMapView::productSample's
    p.placed = true;
  }
  evalBsdfsInLanes(sc, q, h, draws);
}

// A kind's hits shaded (pathShade), their parts worked out first across the queue: each hit's
// interaction and pairs of draws (in lanes at bounceLayout's offsets with Sobol's draws), the
// BSDF samples of the materials with lanes, and the product draws walked level by level.
template <class I, int K>
void runOnHost(const ShadeStage<I, K>& s, int n, HostLanes* h) {
  const WaveQueues& q = s.c.q;
  const SceneView& sc = *s.c.integ.scene;
  const int* slots = q.kindQueue(K);
  const PathParams pp = s.c.integ.shadedPath();
  if (h->inLanes) {
    const BounceLayout layout = bounceLayout(pp);
    for (int j = 0; j < n; ++j) h->lanes.setSampler(j, q.sampler[slots[j]]);
    h->lanes.drawPairs(h->first, n, layout.light, layout.bsdf);
  }
  int draws = 0;
  for (int j = 0; j < n; ++j) {
    const int k = slots[j];
    PreparedHit& p = h->prepared[k];
    p.bsdfDrawn = h->inLanes;
    if (h->inLanes) p.ub = h->lanes.bsdfDraw(j);
    if (prepareHit(sc, q.state[k], q.hit[k], q.sampler[k], pp, h->inLanes, h->inLanes ? h->lanes.lightDraw(j) : Vec2f(),
                   &p, &h->descent[k]))
      h->productDraws[draws++] = k;
  }
  if (h->inLanes) sampleBsdfsInLanes(sc, pp, q, h, slots, n);
  walkProductDraws(sc, q, h, draws);
  for (int j = 0; j < n; ++j) s.shade(slots[j], PreparedParts{sc, h->prepared[slots[j]]});
}

// The queue's shadow rays as one stream, then each answer added to its path.
template <class I>
void runOnHost(const ShadowStage<I>& s, int n, HostLanes* h) {
  const WaveQueues& q = s.c.q;
  s.c.integ.tracer.occludedMany(
      n,
      [&](int i) {
        const LightSampleLd& ld = q.ld[q.shadows[i]];
        return Ray{ld.o, ld.d, ld.tMax};
      },
      [&](int i, bool blocked) { h->blocked[q.shadows[i]] = blocked; });
  for (int i = 0; i < n; ++i) s.resolve(q.shadows[i], h->blocked[q.shadows[i]] != 0);
}

}  // namespace envgi
