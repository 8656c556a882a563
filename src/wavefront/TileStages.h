// The stages of a tile's wavefront on the CPU (TileWavefront.h runs them): each takes the
// round's queue of path slots, does one kind of work for all of them back to back and fills the
// queue the next stage reads. Camera samples → closest hits → escaped rays meet the map → hits
// prepared (interaction, draws, the rough plastics' BSDF samples in lanes) → the product draws
// walked level by level → shading (emission, next-event estimation, the BSDF's next ray) →
// shadow rays → their answers added, and the paths that go on queued for the next round.
// Doing one kind of work for a whole round keeps the BVH, then the map's tables, in cache
// (renderPixel took 4-8% longer on the buddha bench).
#pragma once

#include "wavefront/FilmView.h"
#include "wavefront/MaterialLanes.h"
#include "wavefront/SampleIntegrator.h"
#include "wavefront/SampleSequence.h"

namespace envgi {

// What every stage of one tile's round reads: the tile, its sample, where its queues are.
template <class Integrator>
struct TileRound {
  const Camera& cam;
  const Integrator& integ;
  FilmView film;
  TileQueues* q;
  PixelCounters* counters;
  int x0, y0, x1, y1;
  Sampler first;  // sample s's sampler before its pixel is set: start()'s share done once
  bool inLanes;   // Sobol's draws: the camera samples and the hits' pairs are made in lanes
  const SceneView& scene() const { return *integ.scene; }
};

// The pixels of a tile tw x th, in 4 x 4 blocks, row by row of blocks, where both sides are
// multiples of 4 (16 pixels in a row are then a square, for the camera's packets), else row by
// row: f(k, dx, dy) with k the pixel's index in the tile's row-major order, at (dx, dy) in it.
// Loops, not an index turned into a pixel: that took two integer divisions a camera ray.
template <class F>
inline void forEachTilePixel(int tw, int th, F f) {
  if (tw % 4 == 0 && th % 4 == 0) {
    for (int by = 0; by < th; by += 4)
      for (int bx = 0; bx < tw; bx += 4)
        for (int ly = by; ly < by + 4; ++ly)
          for (int lx = bx; lx < bx + 4; ++lx) f(ly * tw + lx, lx, ly);
  } else {
    for (int dy = 0; dy < th; ++dy)
      for (int dx = 0; dx < tw; ++dx) f(dy * tw + dx, dx, dy);
  }
}

// A path's end: its radiance, times its filter weight, into its pixel's sums.
inline void finishPath(TileQueues* q, int k, const Color& Lpath, PixelCounters* counters) {
  if (!acceptedSample(Lpath, counters)) return;
  const Color L = Lpath * q->weight[k];
  q->acc[k] += L;
  q->accSq[k] += double(luminance(L)) * double(luminance(L));
  q->accW[k] += q->weight[k];
}

// Camera samples: the tile's pixels that take samples queued in q->live (in 4 x 4 blocks, so
// that the camera's packets of 16 are squares). In lanes only their pixels are set, for
// traceCameraLanes; otherwise each gets its sampler, camera ray and path. Returns the count.
template <class I>
int startCameraSamples(const TileRound<I>& r) {
  TileQueues* q = r.q;
  int live = 0;
  forEachTilePixel(r.x1 - r.x0, r.y1 - r.y0, [&](int k, int dx, int dy) {
    const int x = r.x0 + dx, y = r.y0 + dy;
    const uint64_t pixel = uint64_t(y) * uint64_t(r.cam.width) + uint64_t(x);
    if (!r.film.takesSamples(size_t(pixel))) return;
    if (r.inLanes) {
      q->lanes.px[live] = x, q->lanes.py[live] = y;
    } else {
      q->sampler[k] = r.first;
      q->sampler[k].startPixel(pixel);  // startCameraSample's start(), in its two halves
      q->state[k] = r.integ.begin(sampleCameraRay(r.cam, q->sampler[k], x, y, &q->weight[k]));
    }
    q->live[live++] = k;
  });
  return live;
}

// A traced ray's answer for the round's i-th live path.
inline void keepHit(TileQueues* q, int i, bool found, const Hit& h) {
  const int k = q->live[i];
  q->found[k] = found;
  if (found) q->hit[k] = h;
}

// The camera round in lanes: the rays made and traced from the lanes' arrays; a ray that escapes
// adds what it sees (pathAddEscape, the map looked up in lanes at mapUV's coordinates) and ends
// there, and only the rays that hit become paths. Returns the count of those, left in q->live.
template <class I>
int traceCameraLanes(const TileRound<I>& r, int live) {
  TileQueues* q = r.q;
  SampleLanes& lanes = q->lanes;
  const SceneView& sc = r.scene();
  lanes.make(r.cam, r.first, live);
  r.integ.tracer.intersectCoherent(
      live, [&](int i) { return lanes.rayOf(i); }, [&](int i, bool found, const Hit& h) { keepHit(q, i, found, h); });
  r.counters->rays += uint64_t(live);
  int escapes = 0;
  if (sc.hasEnvironment) {
    q->map.findUV(sc.env, live, lanes.dx.data(), lanes.dy.data(), lanes.dz.data());
    for (int i = 0; i < live; ++i)
      if (!q->found[q->live[i]]) q->map.picked[escapes++] = i;
    q->map.lookUp(sc.env, escapes);
  }
  const PathParams pp = r.integ.shadedPath();
  const uint32_t dims = SampleLanes::dimensions(r.cam);
  int hits = 0;
  for (int i = 0, e = 0; i < live; ++i) {
    const int k = q->live[i];
    q->weight[k] = lanes.weight[i];
    if (!q->found[k]) {
      PathState st = pathBegin(lanes.rayOf(i));
      if (sc.hasEnvironment) pathAddEscape(sc, &st, pp, LaneEscapeParts{q->map.uvOf(i), q->map.radianceOf(e++)});
      finishPath(q, k, st.L, r.counters);
      continue;
    }
    q->sampler[k] = r.first;
    q->sampler[k].startPixelAt(lanes.hash[i], dims);
    q->state[k] = r.integ.begin(lanes.rayOf(i));
    q->live[hits++] = k;
  }
  return hits;
}

// Closest hits of the live paths' rays. Coherent camera rays: the tracer may trace them
// together, in the order of q->live (4 x 4 blocks). Incoherent bounce rays: as one stream.
// Then the hit triangles' indices and vertices are asked for, for the whole round before it
// is shaded, so that interaction()'s misses overlap instead of following one another.
template <class I>
void traceClosest(const TileRound<I>& r, int live, bool cameraRays) {
  TileQueues* q = r.q;
  auto rayOfPath = [&](int i) -> const Ray& { return q->state[q->live[i]].ray; };
  auto keep = [&](int i, bool found, const Hit& h) { keepHit(q, i, found, h); };
  if (cameraRays) r.integ.tracer.intersectCoherent(live, rayOfPath, keep);
  else r.integ.tracer.intersectMany(live, rayOfPath, keep);
  r.counters->rays += uint64_t(live);
}
template <class I>
void prefetchHits(const TileRound<I>& r, int live) {
  const TileQueues* q = r.q;
  for (int i = 0; i < live; ++i)
    if (q->found[q->live[i]]) r.scene().prefetchTriangle(q->hit[q->live[i]]);
  for (int i = 0; i < live; ++i)
    if (q->found[q->live[i]]) r.scene().prefetchVertices(q->hit[q->live[i]]);
}

// What pathAddEscape will read from the map for a path whose ray escaped and meets it at uv,
// prefetched where it reads the map's density (past a non-delta bounce).
inline void prefetchEscape(const SceneView& sc, const PathState& st, const PathParams& pp, Vec2f uv) {
  if (sc.hasEnvironment && !st.prevDelta && envSeenByBsdfSampling(pp.envStrategy, false))
    sc.env.prefetchEvalWithPdf(pp.envStrategy, uv, st.prevAxis);
}

// The rays that escaped meet the map: where, lane by lane (MapLanes::findUV), then, past the
// camera's round, what their MIS weights will read there, prefetched.
template <class I>
void meetMap(const TileRound<I>& r, int live, bool cameraRays) {
  if (!r.scene().hasEnvironment) return;
  TileQueues* q = r.q;
  const PathParams pp = r.integ.shadedPath();
  int escapes = 0;
  for (int i = 0; i < live; ++i)
    if (!q->found[q->live[i]]) {
      q->escaped[escapes] = q->live[i];
      q->map.setDirection(escapes++, q->state[q->live[i]].ray.d);
    }
  q->map.findUV(r.scene().env, escapes);
  for (int j = 0; j < escapes; ++j) {
    const int k = q->escaped[j];
    q->prepared[k].uv = q->map.uvOf(j);
    if (!cameraRays) prefetchEscape(r.scene(), q->state[k], pp, q->prepared[k].uv);
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

// The hits queued in q->hits, each prepared (prepareHit; in lanes with Sobol's draws, its light's
// and BSDF's pairs at bounceLayout's offsets), and their BSDF samples in their material kind's
// lanes (MaterialLanes.h). The hits whose light sample is a product draw go to q->productDraws:
// returns their count.
template <class I>
int prepareHits(const TileRound<I>& r, int live) {
  TileQueues* q = r.q;
  SampleLanes& lanes = q->lanes;
  int hits = 0;
  for (int i = 0; i < live; ++i)
    if (q->found[q->live[i]]) q->hits[hits++] = q->live[i];
  const PathParams pp = r.integ.shadedPath();
  const BounceLayout layout = bounceLayout(pp);
  if (r.inLanes) {
    for (int j = 0; j < hits; ++j) lanes.setSampler(j, q->sampler[q->hits[j]]);
    lanes.drawPairs(r.first, hits, layout.light, layout.bsdf);
  }
  int draws = 0;
  for (int j = 0; j < hits; ++j) {
    const int k = q->hits[j];
    PreparedHit& p = q->prepared[k];
    p.bsdfDrawn = r.inLanes;
    if (r.inLanes) p.ub = lanes.bsdfDraw(j);
    if (prepareHit(r.scene(), q->state[k], q->hit[k], q->sampler[k], pp, r.inLanes,
                   r.inLanes ? lanes.lightDraw(j) : Vec2f(), &p, &q->descent[k]))
      q->productDraws[draws++] = k;
  }
  if (r.inLanes) sampleBsdfsInLanes(r.scene(), pp, q, hits);
  return draws;
}

// The product draws' dependent loads a level at a time across the round (ProductDescent), then
// the texels of the pixels they land in, then each draw's end. In lanes, each draw is then placed
// inside its pixel, the map looked up there, and the materials with lanes evaluated in its
// direction.
template <class I>
void walkProductDraws(const TileRound<I>& r, int draws) {
  TileQueues* q = r.q;
  const EnvironmentMapView& env = r.scene().env;
  const int* d = q->productDraws.data();
  for (int i = 0; i < draws; ++i) env.product.descend1(&q->descent[d[i]]);
  for (int i = 0; i < draws; ++i) env.product.descend2(&q->descent[d[i]]);
  for (int i = 0; i < draws; ++i) env.product.descend3(&q->descent[d[i]]);
  for (int i = 0; i < draws; ++i) {
    int px, py;
    if (env.product.descendToPixel(&q->descent[d[i]], &px, &py)) env.prefetchPixel(px, py);
  }
  int placing = 0;
  for (int i = 0; i < draws; ++i) {
    const ProductDescent& a = q->descent[d[i]];
    DescendedDraw& p = q->prepared[d[i]].product;
    p.ended = true;
    p.u = a.u, p.nLocal = a.nLocal;
    p.drawn = env.product.descentEnd(a, &p.uv, &p.pdfUV);
    if (r.inLanes && p.drawn) q->map.setDraw(placing++, p.uv, p.pdfUV);
  }
  if (placing == 0) return;
  q->map.placeDraws(env, placing);
  for (int i = 0, j = 0; i < draws; ++i) {
    DescendedDraw& p = q->prepared[d[i]].product;
    if (!p.drawn) continue;
    q->map.placedDraw(j++, &p.uv, &p.pdfUV, &p.radiance);
    p.dir = env.fromLocal(EnvironmentMapView::uvToDir(p.uv));  // EnvironmentMapView::productSample's
    p.placed = true;
  }
  evalBsdfsInLanes(r.scene(), q, draws);
}

// Keeps a path's next-event sample for the round's shadow rays. st is one of q->state, whose
// index names the path's slot. A sample without a ray adds its zero now, as ShadowRayNow would.
struct ShadowRayLater {
  TileQueues* q;
  void operator()(const LightSampleLd& ld, PathState* st) const {
    const size_t k = size_t(st - q->state.data());
    q->ld[k] = ld;
    q->ldBeta[k] = st->beta;
    if (!ld.needsRay) st->L += st->beta * resolvedLd(ld, false);
  }
};

// Shading: each live path's bounce (pathShade), its next-event sample kept for the shadow
// stage, whose rays are queued in q->shadowRays. Returns their count.
template <class I>
int shadeRound(const TileRound<I>& r, int live) {
  TileQueues* q = r.q;
  for (int i = 0; i < live; ++i) {
    const int k = q->live[i];
    q->ld[k].needsRay = false;
    q->going[k] = r.integ.shade(&q->state[k], q->found[k] != 0, q->hit[k], q->sampler[k], ShadowRayLater{q},
                                PreparedParts{r.scene(), q->prepared[k]});
  }
  int shadows = 0;
  for (int i = 0; i < live; ++i)
    if (q->ld[q->live[i]].needsRay) q->shadowRays[shadows++] = q->live[i];
  return shadows;
}

// The round's shadow rays, back to back (a stream for the tracer).
template <class I>
void traceShadowRays(const TileRound<I>& r, int shadows) {
  TileQueues* q = r.q;
  r.counters->rays += uint64_t(shadows);
  r.integ.tracer.occludedMany(
      shadows,
      [&](int i) {
        const LightSampleLd& ld = q->ld[q->shadowRays[i]];
        return Ray{ld.o, ld.d, ld.tMax};
      },
      [&](int i, bool blocked) { q->blocked[q->shadowRays[i]] = blocked; });
}

// Each path's shadow answer added before anything later in its path, as pathStep adds it; the
// paths that go on stay in q->live for the next round, the others end. Returns the count left.
template <class I>
int resolveRound(const TileRound<I>& r, int live) {
  TileQueues* q = r.q;
  int next = 0;
  for (int i = 0; i < live; ++i) {
    const int k = q->live[i];
    const LightSampleLd& ld = q->ld[k];
    if (ld.needsRay) q->state[k].L += q->ldBeta[k] * resolvedLd(ld, q->blocked[k] != 0);
    if (q->going[k]) q->live[next++] = k;
    else finishPath(q, k, q->state[k].L, r.counters);
  }
  return next;
}

}  // namespace envgi
