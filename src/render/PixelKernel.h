// The per-pixel body of a render pass, written once for the CPU executor and the CUDA kernel:
// a pixel's samples [s0, s1) traced by an integrator and added to the film. Plain data only.
#pragma once

#include <vector>

#include "core/Atomic.h"
#include "integrators/DirectIntegrator.h"
#include "integrators/PathIntegrator.h"
#include "render/RoundLanes.h"
#include "sampling/Sampler.h"

namespace envgi {

// What a pass needs to address a sample: the sequence, its seed and the pixel count it spans.
struct SampleSequence {
  SamplerType type = SamplerType::Independent;
  uint32_t spp = 1;
  uint32_t seed = 0;
};

enum class SampleIntegratorType : int { Path = 0, Direct = 1 };

// direct with at most one light sample and one BSDF sample (the paper's figures' settings,
// the study's strategies) is a path of at most two segments without roulette: the same draws
// in the same order and the same MIS weights (Eq. 6 with nE, nB in {0, 1}; weight 1 where one
// count is 0), so an executor may shade it a bounce at a time as that path.
ENVGI_HD inline bool directIsOneBouncePath(const DirectParams& dp) {
  // The whole collapsed map at each point is not a path's one light sample.
  // The path's weights are the power heuristic's.
  return dp.envStrategy != EnvStrategy::PointsAll && dp.heuristic == MisHeuristic::Power && dp.emitterSamples >= 0 && dp.emitterSamples <= 1 && dp.bsdfSamples >= 0 && dp.bsdfSamples <= 1 &&
         dp.emitterSamples + dp.bsdfSamples > 0;
}
ENVGI_HD inline PathParams directAsPath(const DirectParams& dp) {
  PathParams p;
  p.maxDepth = 2;
  p.rrDepth = 2;  // roulette from depth 2 on, where the path has already ended
  p.hideEmitters = dp.hideEmitters;
  p.envStrategy = dp.envStrategy;
  p.lightSample = dp.emitterSamples > 0;
  p.bsdfSample = dp.bsdfSamples > 0;
  return p;
}

// path or direct over any tracer; the integrators themselves are the shared templates.
template <class Tracer>
struct SampleIntegrator {
  SampleIntegratorType type = SampleIntegratorType::Path;
  PathParams path;
  DirectParams direct;
  const SceneView* scene = nullptr;
  Tracer tracer;

  ENVGI_HD Color operator()(const Ray& ray, Sampler& smp, uint64_t* rays) const {
    return type == SampleIntegratorType::Direct ? directTrace(*scene, tracer, ray, smp, direct, rays)
                                                : pathTrace(*scene, tracer, ray, smp, path, rays);
  }
  // The same sample one bounce a call (regeneratePaths): begin, then step until it returns
  // false; the radiance is then in the state's L. direct is one step.
  ENVGI_HD PathState begin(const Ray& ray) const { return pathBegin(ray); }
  ENVGI_HD bool step(PathState* st, Sampler& smp, uint64_t* rays) const {
    if (type == SampleIntegratorType::Direct) {
      st->L = directTrace(*scene, tracer, st->ray, smp, direct, rays);
      return false;
    }
    return pathStep(*scene, tracer, st, smp, path, rays);
  }
  // step() with the trace taken out, for an executor that traces many paths' rays together
  // (renderTileByBounce): path, and direct where it is a one-bounce path (directAsPath);
  // direct with more samples traces several rays inside its one step.
  ENVGI_HD bool shadesAfterTrace() const {
    return type == SampleIntegratorType::Path || directIsOneBouncePath(direct);
  }
  // The path that shade() follows: path's own, or direct's as a one-bounce path.
  ENVGI_HD PathParams shadedPath() const { return type == SampleIntegratorType::Path ? path : directAsPath(direct); }
  template <class Shadow>
  ENVGI_HD bool shade(PathState* st, bool found, const Hit& h, Sampler& smp, const Shadow& shadow,
                      const ShadeAhead* ahead = nullptr) const {
    return pathShade(*scene, st, found, h, smp, shadedPath(), shadow, ahead);
  }
  // What shade() will read for a path whose ray escaped, asked for ahead (CPU only).
  void prefetchEscape(const PathState& st, Vec2f uv) const { pathPrefetchEscape(*scene, st, shadedPath(), uv); }
  // shade()'s first steps for a hit, done ahead (pathShadeAhead; CPU only).
  bool shadeAhead(const PathState& st, const Hit& h, const Sampler& smp, ShadeAhead* ahead, ProductDrawAhead* draw,
                  const Vec2f* uL = nullptr) const {
    return pathShadeAhead(*scene, st, h, smp, shadedPath(), ahead, draw, uL);
  }
};

// Integrators that run one bounce a call, so regeneratePaths and renderTileByBounce can drive
// them.
template <class T>
struct RunsByBounce {
  static constexpr bool value = false;
};
template <class Tracer>
struct RunsByBounce<SampleIntegrator<Tracer>> {
  static constexpr bool value = true;
};

// What the path and direct kernels run with (Renderer's kernelSettings() fills it from a scene).
struct KernelSettings {
  SampleIntegratorType type = SampleIntegratorType::Path;
  PathParams path;
  DirectParams direct;
  SampleSequence sequence;
  int spp = 1;
};

// The film as the kernels see it: per-pixel sums of radiance and of squared luminance (the
// latter may be null), row-major. Adaptive sampling (AdaptiveSampling.h) sets active: a pixel
// whose entry is 0 has converged and takes no more samples; null means every pixel is active.
struct FilmView {
  Color* sum = nullptr;
  double* sumSqLum = nullptr;
  int width = 0, height = 0;
  const unsigned char* active = nullptr;
  float* weightSum = nullptr;  // the filter's weights summed, for a filter with negative lobes
  ENVGI_HD bool takesSamples(size_t pixel) const { return !active || active[pixel] != 0; }
};

struct PixelCounters {
  uint64_t rays = 0;
  uint64_t dropped = 0;  // NaN, infinite or negative samples, left out of the sums
};

// A sampler over the pass's sequence, to be started per sample.
ENVGI_HD inline Sampler sequenceSampler(const SampleSequence& seq) {
  Sampler smp;
  smp.type = seq.type;
  smp.spp = seq.spp;
  smp.seed = seq.seed;
  return smp;
}

// Starts sample s of pixel (x, y): the sampler at its first dimension, the filter offset, the
// camera ray, and the filter's weight for the sample's radiance. The same (pixel, sample) gives
// the same sample on any device.
ENVGI_HD inline Ray startCameraSample(const Camera& cam, Sampler& smp, int x, int y, int s, float* weight) {
  smp.start(uint64_t(y) * uint64_t(cam.width) + uint64_t(x), uint32_t(s));
  return sampleCameraRay(cam, smp, x, y, weight);
}

// Whether a sample's radiance goes into the film; NaN, infinite or negative ones are counted
// as dropped instead. It is asked of the radiance before the filter's weight, which may be
// negative, multiplies it.
ENVGI_HD inline bool acceptedSample(const Color& L, PixelCounters* counters) {
  if (isFiniteVec(L) && L.x >= 0.f && L.y >= 0.f && L.z >= 0.f) return true;
  ++counters->dropped;
  return false;
}

// Samples [s0, s1) of pixel (x, y).
template <class Integrator>
ENVGI_HD void renderPixel(const Camera& cam, const SampleSequence& seq, const Integrator& integrate, int x, int y,
                          int s0, int s1, FilmView film, PixelCounters* counters) {
  size_t pixel = size_t(y) * size_t(cam.width) + size_t(x);
  if (!film.takesSamples(pixel)) return;
  Sampler smp = sequenceSampler(seq);
  Color acc(0.f);
  double accSq = 0.0;
  float accW = 0.f;
  for (int s = s0; s < s1; ++s) {
    float w;
    Color L = integrate(startCameraSample(cam, smp, x, y, s, &w), smp, &counters->rays);
    if (!acceptedSample(L, counters)) continue;
    L *= w;
    acc += L;
    accSq += double(luminance(L)) * double(luminance(L));
    accW += w;
  }
  film.sum[pixel] += acc;
  if (film.sumSqLum) film.sumSqLum[pixel] += accSq;
  if (film.weightSum) film.weightSum[pixel] += accW;
}

// Samples [s0, s1) of every pixel by path regeneration (Novak et al. 2010), for a GPU thread:
// whenever its path ends, the thread takes the next (pixel, sample) from fetch() (items numbered
// sample-major, so a warp's fresh items are neighbouring pixels) instead of idling while its
// warp's longest path finishes. Any thread may finish any pixel's sample, so the film sums are
// added atomically. With one thread and a counting fetch it adds each pixel's samples in the
// order renderPixel does, so a fresh film gets the same sums bit for bit.
template <class Integrator, class Fetch>
ENVGI_HD void regeneratePaths(const Camera& cam, const SampleSequence& seq, const Integrator& integ, int s0, int s1,
                              FilmView film, Fetch fetch, PixelCounters* counters) {
  const uint64_t npix = uint64_t(cam.width) * uint64_t(cam.height), total = npix * uint64_t(s1 - s0);
  Sampler smp = sequenceSampler(seq);
  PathState st = integ.begin(Ray{});
  uint64_t pixel = 0;
  float w = 1.f;
  bool active = false;
  for (;;) {
    if (!active) {
      uint64_t item = fetch();
      if (item >= total) break;
      pixel = item % npix;
      if (!film.takesSamples(pixel)) continue;  // converged: its item costs one fetch
      int x = int(pixel % uint64_t(cam.width)), y = int(pixel / uint64_t(cam.width));
      st = integ.begin(startCameraSample(cam, smp, x, y, s0 + int(item / npix), &w));
    }
    active = integ.step(&st, smp, &counters->rays);
    if (!active && acceptedSample(st.L, counters)) {
      st.L *= w;
      if (film.weightSum) atomicAddRelaxed(&film.weightSum[pixel], w);
      atomicAddRelaxed(&film.sum[pixel].x, st.L.x);
      atomicAddRelaxed(&film.sum[pixel].y, st.L.y);
      atomicAddRelaxed(&film.sum[pixel].z, st.L.z);
      if (film.sumSqLum) atomicAddRelaxed(&film.sumSqLum[pixel], double(luminance(st.L)) * double(luminance(st.L)));
    }
  }
}

// Per-thread room for renderTileByBounce: one path, sampler and hit per pixel of a tile,
// allocated once per thread, never per ray.
struct TileBatch {
  std::vector<PathState> state;
  std::vector<Sampler> sampler;
  std::vector<Hit> hit;
  std::vector<unsigned char> found, going, blocked;
  std::vector<int> active, shadow;  // shadow: the round's paths whose light sample has a ray
  std::vector<LightSampleLd> ld;  // each path's next-event sample of this round
  std::vector<Color> ldBeta;      // and the path's beta when it was drawn
  std::vector<float> weight;      // each path's filter weight
  std::vector<Color> acc;
  std::vector<double> accSq;
  std::vector<float> accW;
  std::vector<ShadeAhead> ahead;        // each hit's interaction and light draw, worked out ahead
  std::vector<ProductDrawAhead> draw;   // the round's product draws, walked level by level
  std::vector<int> drawing;             // the round's paths with such a draw
  std::vector<int> escaping;            // the round's paths whose ray escaped
  std::vector<int> hitting;             // and those whose ray hit
  std::vector<int> sampling, picking;   // hits whose BSDF samples go to the lanes; one material's
  RoundLanes lanes;                     // the round's work done lane by lane
  void resize(size_t n) {
    if (state.size() >= n) return;
    state.resize(n), sampler.resize(n), hit.resize(n), found.resize(n), going.resize(n), blocked.resize(n);
    active.resize(n), shadow.resize(n);
    ld.resize(n), ldBeta.resize(n), weight.resize(n), acc.resize(n), accSq.resize(n), accW.resize(n);
    ahead.resize(n), draw.resize(n), drawing.resize(n), escaping.resize(n), hitting.resize(n);
    sampling.resize(n), picking.resize(n);
    lanes.resize(n);
  }
};

// Lanes over the hits b->sampling[0, count), a material at a time: put(n, k) sets lane n from
// hit k, run(material, n) runs lanes [0, n), take(j, k) reads lane j back into hit k.
template <class Put, class Run, class Take>
inline void byMaterial(TileBatch* b, int count, Put put, Run run, Take take) {
  int left = count;
  while (left > 0) {
    const int material = b->ahead[b->sampling[0]].si.bsdf;
    int n = 0, rest = 0;
    for (int i = 0; i < left; ++i) {
      const int k = b->sampling[i];
      if (b->ahead[k].si.bsdf != material) {
        b->sampling[rest++] = k;
        continue;
      }
      b->picking[n] = k;
      put(n++, k);
    }
    run(material, n);
    for (int j = 0; j < n; ++j) take(j, b->picking[j]);
    left = rest;
  }
}

// What pathShade's woLocal is for hit k (its interaction found ahead).
inline Vec3f aheadWo(const TileBatch* b, int k) { return b->ahead[k].si.shading.toLocal(-b->state[k].ray.d); }

// The BSDF samples of a round's hits on rough plastics (RoundLanes::samplesInLanes), worked out
// in vector lanes a material at a time into each hit's ahead.bs, from the pairs drawn ahead
// (ahead.ub): pathShade then takes them (drawBsdfSample). Hits [0, hits) of b->hitting, their
// interactions found (pathShadeAhead); a path that ends before its BSDF sample is left out.
inline void sampleBsdfsInLanes(const SceneView& sc, const PathParams& pp, TileBatch* b, int hits) {
  if (!pp.bsdfSample) return;
  int count = 0;
  for (int j = 0; j < hits; ++j) {
    const int k = b->hitting[j];
    if (!(pp.maxDepth >= 0 && b->state[k].depth >= pp.maxDepth) &&
        RoundLanes::samplesInLanes(sc.bsdfs[b->ahead[k].si.bsdf]))
      b->sampling[count++] = k;
  }
  RoundLanes& lanes = b->lanes;
  byMaterial(
      b, count, [&](int n, int k) { lanes.setBsdfDraw(n, aheadWo(b, k), b->ahead[k].ub); },
      [&](int material, int n) { lanes.sampleRoughPlastic(sc.bsdfs[material], n); },
      [&](int j, int k) {
        BsdfSampleAhead& s = b->ahead[k].bs;
        s.ok = lanes.bsdfSampleOf(j, &s.s);
        s.made = true;
      });
}

// The same BSDFs evaluated in lanes for their light samples' directions, where the light sample
// is a product draw placed ahead (ahead.product): the draw's world direction is worked out here,
// which EnvironmentMapView::sample then takes, and prepareLd takes the value and density
// (BsdfEvalAhead) for that direction. Hits [0, draws) of b->drawing; a hit with a blend's
// partner is left out (prepareLd evaluates the two together).
inline void evalBsdfsInLanes(const SceneView& sc, TileBatch* b, int draws) {
  int count = 0;
  for (int i = 0; i < draws; ++i) {
    const int k = b->drawing[i];
    const ShadeAhead& a = b->ahead[k];
    if (a.product.drawn && a.product.placed && a.si.partner < 0 && RoundLanes::samplesInLanes(sc.bsdfs[a.si.bsdf]))
      b->sampling[count++] = k;
  }
  RoundLanes& lanes = b->lanes;
  const EnvironmentMapView& env = sc.env;
  byMaterial(
      b, count,
      [&](int n, int k) {
        ProductDraw& d = b->ahead[k].product;
        d.dir = env.fromLocal(EnvironmentMapView::uvToDir(d.uv));  // sample()'s, for the placed draw
        d.directed = true;
        lanes.setBsdfEval(n, aheadWo(b, k), b->ahead[k].si.shading.toLocal(d.dir));  // prepareLd's wiLocal
      },
      [&](int material, int n) { lanes.evalRoughPlastic(sc.bsdfs[material], n); },
      [&](int j, int k) { b->ahead[k].ev = lanes.bsdfEvalOf(j); });
}

// Keeps a path's next-event sample for the round's shadow rays (renderTileByBounce; CPU only).
// st is one of b->state, whose index names the path's slots. A sample without a ray adds its
// zero now, as ShadowRayNow would.
struct ShadowRayLater {
  TileBatch* b;
  void operator()(const LightSampleLd& ld, PathState* st) const {
    size_t k = size_t(st - b->state.data());
    b->ld[k] = ld;
    b->ldBeta[k] = st->beta;
    if (!ld.needsRay) st->L += st->beta * resolvedLd(ld, false);
  }
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

// Samples [s0, s1) of the tile [x0, x1) x [y0, y1) a bounce at a time (CPU): sample s of every
// pixel starts together, then each round traces all live paths' rays back to back and shades
// them back to back, instead of alternating one ray's traversal with its shading. That keeps
// the BVH, then the map's tables, in cache across a round (renderPixel took 4-8% longer on the
// buddha bench: docs/performance.md). The camera rays go to the tracer together, for packets,
// and each round's bounce rays and shadow rays, for streams.
// Each pixel adds its samples in renderPixel's order, so the film's sums are the same to the
// bit where the tracer's packets give one-ray hits to the bit (the BVH's loop does; Embree's
// packets round t in their own way).
template <class Integrator>
void renderTileByBounce(const Camera& cam, const SampleSequence& seq, const Integrator& integ, int x0, int y0, int x1,
                        int y1, int s0, int s1, FilmView film, TileBatch* b, PixelCounters* counters) {
  const int tw = x1 - x0, n = tw * (y1 - y0);
  b->resize(size_t(n));
  for (int k = 0; k < n; ++k) b->acc[k] = Color(0.f), b->accSq[k] = 0.0, b->accW[k] = 0.f;
  for (int s = s0; s < s1; ++s) {
    int live = 0;
    // Every pixel's sampler starts from this one: sample s's share of start() is done once.
    Sampler first = sequenceSampler(seq);
    first.setIndex(uint32_t(s));
    // With Sobol's draws, the round's camera samples are made lane by lane (RoundLanes).
    const bool inLanes = RoundLanes::handles(first);
    RoundLanes& lanes = b->lanes;
    // The tile's pixels in 4 x 4 blocks, so that the camera's packets of 16 are squares.
    forEachTilePixel(tw, y1 - y0, [&](int k, int dx, int dy) {
      const int x = x0 + dx, y = y0 + dy;
      const uint64_t pixel = uint64_t(y) * uint64_t(cam.width) + uint64_t(x);
      if (!film.takesSamples(size_t(pixel))) return;
      if (inLanes) {
        lanes.px[live] = x, lanes.py[live] = y;
      } else {
        b->sampler[k] = first;
        b->sampler[k].startPixel(pixel);  // startCameraSample's start(), in its two halves
        b->state[k] = integ.begin(sampleCameraRay(cam, b->sampler[k], x, y, &b->weight[k]));
      }
      b->active[live++] = k;
    });
    // A traced ray's answer for the round's i-th path.
    auto keepHit = [&](int i, bool found, const Hit& h) {
      const int k = b->active[i];
      b->found[k] = found;
      if (found) b->hit[k] = h;
    };
    // A path's end: its radiance, times its filter weight, into its pixel's sums.
    auto finish = [&](int k, const Color& Lpath) {
      if (!acceptedSample(Lpath, counters)) return;
      const Color L = Lpath * b->weight[k];
      b->acc[k] += L;
      b->accSq[k] += double(luminance(L)) * double(luminance(L));
      b->accW[k] += b->weight[k];
    };
    // Made in lanes, the camera round is traced from the lanes' arrays; a ray that escapes adds
    // what it sees (cameraEscape, where the map is looked up from mapUV's coordinates) and ends
    // there, and only the rays that hit become paths (a sampler and a PathState each).
    const bool laneRound = inLanes && live > 0;
    if (laneRound) {
      lanes.make(cam, first, live);
      integ.tracer.intersectCoherent(live, [&](int i) { return lanes.rayOf(i); }, keepHit);
      counters->rays += uint64_t(live);
      const SceneView& sc = *integ.scene;
      // The escaped rays' radiance, lane by lane, where they meet the map.
      int escapes = 0;
      if (sc.hasEnvironment) {
        lanes.mapUV(sc.env, live);
        for (int i = 0; i < live; ++i)
          if (!b->found[b->active[i]]) lanes.picked[escapes++] = i;
        lanes.mapRadiance(sc.env, escapes);
      }
      const PathParams pp = integ.shadedPath();
      const uint32_t dims = RoundLanes::dimensions(cam);
      int hits = 0;
      for (int i = 0, e = 0; i < live; ++i) {
        const int k = b->active[i];
        b->weight[k] = lanes.weight[i];
        if (!b->found[k]) {
          const Vec2f uv = lanes.uvOf(i);
          const Color Le = sc.hasEnvironment ? lanes.radianceOf(e++) : Color(0.f);
          finish(k, cameraEscape(sc, lanes.rayOf(i), pp, sc.hasEnvironment ? &uv : nullptr,
                                 sc.hasEnvironment ? &Le : nullptr));
          continue;
        }
        b->sampler[k] = first;
        b->sampler[k].startPixelAt(lanes.hash[i], dims);
        b->state[k] = integ.begin(lanes.rayOf(i));
        b->active[hits++] = k;
      }
      live = hits;
    }
    for (bool cameraRays = true; live > 0; cameraRays = false) {
      // A camera round made in lanes was traced above: every path left is a hit.
      if (!(cameraRays && laneRound)) {
        auto rayOfPath = [&](int i) -> const Ray& { return b->state[b->active[i]].ray; };
        // Coherent camera rays: the tracer may trace them together, in the order of b->active,
        // which takes the tile's pixels in 4 x 4 blocks (forEachTilePixel). Incoherent bounce
        // rays: the tracer may trace them as one stream.
        if (cameraRays) integ.tracer.intersectCoherent(live, rayOfPath, keepHit);
        else integ.tracer.intersectMany(live, rayOfPath, keepHit);
        counters->rays += uint64_t(live);
      }
      // Ask for the hit triangles' indices, then their vertices, for the whole round before
      // shading it, so that interaction()'s misses overlap instead of following one another;
      // likewise the map's texels and cdf steps that the escaped rays' MIS weights read.
      // Then shade, then trace the round's shadow rays back to back, each adding what got
      // through before anything later in its path, as pathStep adds it.
      for (int i = 0; i < live; ++i)
        if (b->found[b->active[i]]) integ.scene->prefetchTriangle(b->hit[b->active[i]]);
      for (int i = 0; i < live; ++i)
        if (b->found[b->active[i]]) integ.scene->prefetchVertices(b->hit[b->active[i]]);
      // The rays that escaped meet the map: where, lane by lane (RoundLanes::mapUV), then, past
      // the camera's round, what their MIS weights read there, asked for ahead.
      const bool seesMap = integ.scene->hasEnvironment;
      if (seesMap) {
        int escapes = 0;
        for (int i = 0; i < live; ++i)
          if (!b->found[b->active[i]]) {
            b->escaping[escapes] = b->active[i];
            lanes.setDirection(escapes++, b->state[b->active[i]].ray.d);
          }
        lanes.mapUV(integ.scene->env, escapes);
        for (int j = 0; j < escapes; ++j) {
          ShadeAhead& a = b->ahead[b->escaping[j]];
          a.escaped = true;
          a.uv = lanes.uvOf(j);
          if (!cameraRays) integ.prefetchEscape(b->state[b->escaping[j]], a.uv);
        }
      }
      // Each hit's interaction and light draw, then the product draws' dependent loads a level
      // at a time across the round (CosineProductView::aheadLevel0-4), then the texels of the
      // pixels they land in: shading then finds them in cache.
      // With Sobol's draws, the hits' light and BSDF pairs are drawn first, lane by lane.
      int hits = 0;
      for (int i = 0; i < live; ++i)
        if (b->found[b->active[i]]) b->hitting[hits++] = b->active[i];
      const PathParams& pp = integ.shadedPath();
      const BounceLayout layout = bounceLayout(pp);
      if (inLanes) {
        for (int j = 0; j < hits; ++j) lanes.setSampler(j, b->sampler[b->hitting[j]]);
        lanes.drawAhead(first, hits, layout.light, layout.bsdf);
      }
      int draws = 0;
      for (int j = 0; j < hits; ++j) {
        const int k = b->hitting[j];
        const Vec2f uL = inLanes ? lanes.lightDraw(j) : Vec2f();
        b->ahead[k].bsdfDrawn = inLanes;
        if (inLanes) b->ahead[k].ub = lanes.bsdfDraw(j);
        if (integ.shadeAhead(b->state[k], b->hit[k], b->sampler[k], &b->ahead[k], &b->draw[k], inLanes ? &uL : nullptr))
          b->drawing[draws++] = k;
      }
      if (inLanes) sampleBsdfsInLanes(*integ.scene, pp, b, hits);
      const EnvironmentMapView& env = integ.scene->env;
      for (int i = 0; i < draws; ++i) env.product.aheadLevel1(&b->draw[b->drawing[i]]);
      for (int i = 0; i < draws; ++i) env.product.aheadLevel2(&b->draw[b->drawing[i]]);
      for (int i = 0; i < draws; ++i) env.product.aheadLevel3(&b->draw[b->drawing[i]]);
      for (int i = 0; i < draws; ++i) {
        int px, py;
        if (env.product.aheadLevel4(&b->draw[b->drawing[i]], &px, &py)) env.prefetchPixel(px, py);
      }
      // Each draw's end, from what the levels loaded: prepareLd takes it instead of drawing again.
      // With the lanes, each draw is then placed inside its pixel and the map looked up there.
      int placing = 0;
      for (int i = 0; i < draws; ++i) {
        ShadeAhead& a = b->ahead[b->drawing[i]];
        a.product = env.product.aheadDraw(b->draw[b->drawing[i]]);
        a.productAhead = true;
        if (inLanes && a.product.drawn) lanes.setDraw(placing++, a.product.uv, a.product.pdfUV);
      }
      if (placing > 0) {
        lanes.placeDraws(env, placing);
        for (int i = 0, j = 0; i < draws; ++i) {
          ProductDraw& d = b->ahead[b->drawing[i]].product;
          if (!d.drawn) continue;
          lanes.placedDraw(j++, &d.uv, &d.pdfUV, &d.radiance);
          d.placed = true;
        }
        evalBsdfsInLanes(*integ.scene, b, draws);
      }
      for (int i = 0; i < live; ++i) {
        int k = b->active[i];
        b->ld[k].needsRay = false;
        b->going[k] = integ.shade(&b->state[k], b->found[k] != 0, b->hit[k], b->sampler[k], ShadowRayLater{b},
                                  b->found[k] || seesMap ? &b->ahead[k] : nullptr);
      }
      int shadows = 0;
      for (int i = 0; i < live; ++i)
        if (b->ld[b->active[i]].needsRay) b->shadow[shadows++] = b->active[i];
      counters->rays += uint64_t(shadows);
      integ.tracer.occludedMany(
          shadows, [&](int i) { const LightSampleLd& ld = b->ld[b->shadow[i]]; return Ray{ld.o, ld.d, ld.tMax}; },
          [&](int i, bool blocked) { b->blocked[b->shadow[i]] = blocked; });
      int next = 0;
      for (int i = 0; i < live; ++i) {
        int k = b->active[i];
        const LightSampleLd& ld = b->ld[k];
        if (ld.needsRay) b->state[k].L += b->ldBeta[k] * resolvedLd(ld, b->blocked[k] != 0);
        if (b->going[k]) {
          b->active[next++] = k;
        } else {
          finish(k, b->state[k].L);
        }
      }
      live = next;
    }
  }
  for (int k = 0; k < n; ++k) {
    size_t pixel = size_t(y0 + k / tw) * size_t(cam.width) + size_t(x0 + k % tw);
    if (!film.takesSamples(pixel)) continue;
    film.sum[pixel] += b->acc[k];
    if (film.sumSqLum) film.sumSqLum[pixel] += b->accSq[k];
    if (film.weightSum) film.weightSum[pixel] += b->accW[k];
  }
}

}  // namespace envgi
