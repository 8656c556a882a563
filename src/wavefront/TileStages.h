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
// adds what it sees (cameraEscape, the map looked up at mapUV's coordinates) and ends there, and
// only the rays that hit become paths. Returns the count of those, left in q->live.
template <class I>
int traceCameraLanes(const TileRound<I>& r, int live) {
  TileQueues* q = r.q;
  RoundLanes& lanes = q->lanes;
  const SceneView& sc = r.scene();
  lanes.make(r.cam, r.first, live);
  r.integ.tracer.intersectCoherent(
      live, [&](int i) { return lanes.rayOf(i); }, [&](int i, bool found, const Hit& h) { keepHit(q, i, found, h); });
  r.counters->rays += uint64_t(live);
  int escapes = 0;
  if (sc.hasEnvironment) {
    lanes.mapUV(sc.env, live);
    for (int i = 0; i < live; ++i)
      if (!q->found[q->live[i]]) lanes.picked[escapes++] = i;
    lanes.mapRadiance(sc.env, escapes);
  }
  const PathParams pp = r.integ.shadedPath();
  const uint32_t dims = RoundLanes::dimensions(r.cam);
  int hits = 0;
  for (int i = 0, e = 0; i < live; ++i) {
    const int k = q->live[i];
    q->weight[k] = lanes.weight[i];
    if (!q->found[k]) {
      const Vec2f uv = lanes.uvOf(i);
      const Color Le = sc.hasEnvironment ? lanes.radianceOf(e++) : Color(0.f);
      finishPath(q, k,
                 cameraEscape(sc, lanes.rayOf(i), pp, sc.hasEnvironment ? &uv : nullptr,
                              sc.hasEnvironment ? &Le : nullptr),
                 r.counters);
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

// The rays that escaped meet the map: where, lane by lane (RoundLanes::mapUV), then, past the
// camera's round, what their MIS weights will read there, asked for ahead.
template <class I>
void meetMap(const TileRound<I>& r, int live, bool cameraRays) {
  if (!r.scene().hasEnvironment) return;
  TileQueues* q = r.q;
  int escapes = 0;
  for (int i = 0; i < live; ++i)
    if (!q->found[q->live[i]]) {
      q->escaped[escapes] = q->live[i];
      q->lanes.setDirection(escapes++, q->state[q->live[i]].ray.d);
    }
  q->lanes.mapUV(r.scene().env, escapes);
  for (int j = 0; j < escapes; ++j) {
    ShadeAhead& a = q->ahead[q->escaped[j]];
    a.escaped = true;
    a.uv = q->lanes.uvOf(j);
    if (!cameraRays) r.integ.prefetchEscape(q->state[q->escaped[j]], a.uv);
  }
}

// The hits queued in q->hits, each with its interaction and light draw (in lanes with Sobol's
// draws, at bounceLayout's offsets, with the BSDF's pair), and the rough plastics' BSDF samples
// in lanes. The hits whose light sample is a product draw go to q->productDraws: returns their
// count.
template <class I>
int prepareHits(const TileRound<I>& r, int live) {
  TileQueues* q = r.q;
  RoundLanes& lanes = q->lanes;
  int hits = 0;
  for (int i = 0; i < live; ++i)
    if (q->found[q->live[i]]) q->hits[hits++] = q->live[i];
  const PathParams pp = r.integ.shadedPath();
  const BounceLayout layout = bounceLayout(pp);
  if (r.inLanes) {
    for (int j = 0; j < hits; ++j) lanes.setSampler(j, q->sampler[q->hits[j]]);
    lanes.drawAhead(r.first, hits, layout.light, layout.bsdf);
  }
  int draws = 0;
  for (int j = 0; j < hits; ++j) {
    const int k = q->hits[j];
    const Vec2f uL = r.inLanes ? lanes.lightDraw(j) : Vec2f();
    q->ahead[k].bsdfDrawn = r.inLanes;
    if (r.inLanes) q->ahead[k].ub = lanes.bsdfDraw(j);
    if (r.integ.shadeAhead(q->state[k], q->hit[k], q->sampler[k], &q->ahead[k], &q->draw[k], r.inLanes ? &uL : nullptr))
      q->productDraws[draws++] = k;
  }
  if (r.inLanes) sampleBsdfsInLanes(r.scene(), pp, q, hits);
  return draws;
}

// The product draws' dependent loads a level at a time across the round
// (CosineProductView::aheadLevel1-4), then the texels of the pixels they land in, then each
// draw's end, which prepareLd takes instead of drawing again. In lanes, each draw is then placed
// inside its pixel, the map looked up there, and the rough plastics evaluated at it.
template <class I>
void walkProductDraws(const TileRound<I>& r, int draws) {
  TileQueues* q = r.q;
  const EnvironmentMapView& env = r.scene().env;
  const int* d = q->productDraws.data();
  for (int i = 0; i < draws; ++i) env.product.aheadLevel1(&q->draw[d[i]]);
  for (int i = 0; i < draws; ++i) env.product.aheadLevel2(&q->draw[d[i]]);
  for (int i = 0; i < draws; ++i) env.product.aheadLevel3(&q->draw[d[i]]);
  for (int i = 0; i < draws; ++i) {
    int px, py;
    if (env.product.aheadLevel4(&q->draw[d[i]], &px, &py)) env.prefetchPixel(px, py);
  }
  int placing = 0;
  for (int i = 0; i < draws; ++i) {
    ShadeAhead& a = q->ahead[d[i]];
    a.product = env.product.aheadDraw(q->draw[d[i]]);
    a.productAhead = true;
    if (r.inLanes && a.product.drawn) q->lanes.setDraw(placing++, a.product.uv, a.product.pdfUV);
  }
  if (placing == 0) return;
  q->lanes.placeDraws(env, placing);
  for (int i = 0, j = 0; i < draws; ++i) {
    ProductDraw& p = q->ahead[d[i]].product;
    if (!p.drawn) continue;
    q->lanes.placedDraw(j++, &p.uv, &p.pdfUV, &p.radiance);
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
  const bool seesMap = r.scene().hasEnvironment;
  for (int i = 0; i < live; ++i) {
    const int k = q->live[i];
    q->ld[k].needsRay = false;
    q->going[k] = r.integ.shade(&q->state[k], q->found[k] != 0, q->hit[k], q->sampler[k], ShadowRayLater{q},
                                q->found[k] || seesMap ? &q->ahead[k] : nullptr);
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
