// The stages of a wave of paths (WaveQueues.h), each a function of one index into its queue that
// host and device run alike: the GPU a thread an index (CudaStageLaunch.cuh), the CPU a wave a
// tile through each stage's batch form for its whole queue (HostStages.h, HostStageLaunch.h). Camera samples → closest hits, queued as escaped rays
// or by the shade kind of the material hit → escaped rays see the map → hits shaded, a stage per
// kind (emission, the next-event sample queued as a shadow ray, the BSDF's next ray) → shadow
// rays → the pass's sums added to the film (direct that is no one-bounce path: camera samples →
// DirectSampleStage → the film). pathShade is the physics; a stage only says where its inputs
// come from and where its outputs go, and a shade stage's Parts hold only its kind's BSDF code
// (TypedParts), so a GPU kernel per kind holds no other material's code.
//
// A wave takes (pixel, sample) items [base, base + n) of the pass, numbered sample-major, with n
// at most the film's pixels: a wave then holds at most one sample of a pixel, whose sums take
// its samples in renderPixel's order, and a pass adds renderPixel's sums to the bit over a
// tracer whose hits are the same.
#pragma once

#include "wavefront/SampleIntegrator.h"
#include "wavefront/SampleSequence.h"
#include "wavefront/WaveQueues.h"

namespace envgi {

// The film's pixels a pass takes: the whole film (a GPU's pass) or a tile of it (a CPU thread's,
// whose wave then stays in its caches). Its pixels are numbered in 4 x 4 blocks, row by row of
// blocks, where both sides are multiples of 4 (16 neighbours: a square, for the camera rays'
// packets), else row by row; the pass's sums are kept by the pixel's row-major place in it.
struct WaveRegion {
  int x0 = 0, y0 = 0, w = 0, h = 0;
  ENVGI_HD uint64_t pixels() const { return uint64_t(w) * uint64_t(h); }
  ENVGI_HD bool inBlocks() const { return w % 4 == 0 && h % 4 == 0; }
  // The k-th pixel's place (dx, dy) in the region.
  ENVGI_HD void at(int k, int* dx, int* dy) const {
    if (!inBlocks()) {
      *dx = k % w, *dy = k / w;
      return;
    }
    const int block = k >> 4, bw = w >> 2;
    *dx = (block % bw) * 4 + (k & 3), *dy = (block / bw) * 4 + ((k >> 2) & 3);
  }
  ENVGI_HD size_t filmPixel(int dx, int dy, int filmWidth) const {
    return size_t(y0 + dy) * size_t(filmWidth) + size_t(x0 + dx);
  }
};

// What every stage reads: the integrator (path or direct), the camera and sample sequence, the
// film and the region of it the pass takes, the wave's queues and the pass's sums.
template <class I>
struct WaveContext {
  I integ;
  Camera cam;
  SampleSequence seq;
  FilmView film;
  WaveRegion region;
  WaveQueues q;
  WaveSums sums;
};

// A path's sample, ended: its radiance times its filter weight into its pixel's sums, as
// renderPixel adds it (no two paths of a wave share a pixel, so the adds need no atomics).
ENVGI_HD inline void addWaveSample(const WaveQueues& q, const WaveSums& sums, int slot, Color L) {
  PixelCounters pc;
  if (!acceptedSample(L, &pc)) {
    atomicAddRelaxed(&q.counts->dropped, 1u);
    return;
  }
  const float w = q.weight[slot];
  const uint32_t p = q.pixel[slot];
  L *= w;
  sums.acc[p] += L;
  sums.accSq[p] += double(luminance(L)) * double(luminance(L));
  sums.accW[p] += w;
}

// A path's next-event sample kept for the shadow stage (pathShade's Shadow): its ray queued, or,
// without one, its zero added now, as ShadowRayNow would.
struct ShadowToQueue {
  LightSampleLd* ld;
  Color* ldBeta;
  int* shadows;
  int* count;
  int slot;
  ENVGI_HD void operator()(const LightSampleLd& s, PathState* st) const {
    ld[slot] = s;
    ldBeta[slot] = st->beta;
    if (s.needsRay) WaveQueues::push(shadows, count, slot);
    else st->L += st->beta * resolvedLd(s, false);
  }
  ENVGI_HD static ShadowToQueue of(const WaveQueues& q, int slot) {
    return {q.ld, q.ldBeta, q.shadows, &q.counts->round.shadows, slot};
  }
};

// Item base + i (pixel (base + i) % pixels of the region, in its order; sample s0 + (base + i) /
// pixels): its sampler, camera ray and filter weight into slot i, queued as a ray of the
// round of parity 0. Pixels that take no more samples (adaptive sampling) start no path.
template <class I>
struct CameraStage {
  WaveContext<I> c;
  uint64_t base;
  int s0;
  ENVGI_HD void operator()(int i) const {
    const uint64_t npix = c.region.pixels(), item = base + uint64_t(i);
    int dx, dy;
    c.region.at(int(item % npix), &dx, &dy);
    if (!c.film.takesSamples(c.region.filmPixel(dx, dy, c.cam.width))) return;
    Sampler smp = sequenceSampler(c.seq);
    float w;
    const Ray ray = startCameraSample(c.cam, smp, c.region.x0 + dx, c.region.y0 + dy, s0 + int(item / npix), &w);
    start(i, ray, smp, w, dx, dy);
  }
  // Slot i's path, begun with its camera ray.
  ENVGI_HD void start(int i, const Ray& ray, const Sampler& smp, float w, int dx, int dy) const {
    c.q.state[i] = c.integ.begin(ray);
    c.q.sampler[i] = smp;
    c.q.weight[i] = w;
    c.q.pixel[i] = uint32_t(dy * c.region.w + dx);
    WaveQueues::push(c.q.rayQueue(0), &c.q.counts->round.rays[0], i);
  }
};

// The round's rays traced: a miss is queued as escaped, a hit by the shade kind of its material.
template <class I>
struct ClosestHitStage {
  WaveContext<I> c;
  int parity;
  bool cameraRound;  // the camera's rays: coherent, for a tracer that traces them together
  ENVGI_HD void operator()(int i) const {
    const WaveQueues& q = c.q;
    const int slot = q.rayQueue(parity)[i];
    queue(slot, c.integ.tracer.intersect(q.state[slot].ray, &q.hit[slot]));
  }
  ENVGI_HD void queue(int slot, bool found) const {
    const WaveQueues& q = c.q;
    if (!found) {
      WaveQueues::push(q.escaped, &q.counts->round.escaped, slot);
      return;
    }
    const SceneView& sc = *c.integ.scene;
    const int kind = shadeKindOf(sc.bsdfs[sc.bsdfIndexAt(q.hit[slot])]);
    WaveQueues::push(q.kindQueue(kind), &q.counts->round.kinds[kind], slot);
  }
};

// An escaped ray sees the map (pathShade's escape), and its path ends.
template <class I>
struct EscapeStage {
  WaveContext<I> c;
  bool cameraRound;
  ENVGI_HD void operator()(int i) const { escape(c.q.escaped[i], SampledParts{*c.integ.scene}); }
  // parts: where the map's place and radiance come from (mapUV, mapRadiance).
  template <class Parts>
  ENVGI_HD void escape(int slot, const Parts& parts) const {
    PathState& st = c.q.state[slot];
    pathAddEscape(*c.integ.scene, &st, c.integ.shadedPath(), parts);
    addWaveSample(c.q, c.sums, slot, st.L);
  }
};

// The Parts a shade stage of a kind shades with: a type's own code, or every type's for blends.
template <int Kind>
struct ShadeKindParts {
  using type = TypedParts<BsdfType(Kind)>;
};
template <>
struct ShadeKindParts<kBlendShadeKind> {
  using type = SampledParts;
};

// The hits of one shade kind shaded (pathShade): a path that goes on is queued as a ray of the
// next round; one that ends without a shadow ray to wait for ends here.
template <class I, int Kind>
struct ShadeStage {
  WaveContext<I> c;
  int parity;
  ENVGI_HD void operator()(int i) const {
    using Parts = typename ShadeKindParts<Kind>::type;
    shade(c.q.kindQueue(Kind)[i], Parts{{*c.integ.scene}});
  }
  template <class Parts>
  ENVGI_HD void shade(int slot, const Parts& parts) const {
    const WaveQueues& q = c.q;
    // The path and its sampler shaded where they lie: copies of them spilled on the GPU.
    PathState& st = q.state[slot];
    q.ld[slot].needsRay = false;
    const bool going =
        c.integ.shade(&st, true, q.hit[slot], q.sampler[slot], ShadowToQueue::of(q, slot), parts);
    q.going[slot] = going;
    if (going) WaveQueues::push(q.rayQueue(parity ^ 1), &q.counts->round.rays[parity ^ 1], slot);
    else if (!q.ld[slot].needsRay) addWaveSample(q, c.sums, slot, st.L);
  }
};

// The round's shadow rays: each answer added to its path before anything later in it, as
// pathStep adds it; a path that ended with this round's shading ends here.
template <class I>
struct ShadowStage {
  WaveContext<I> c;
  ENVGI_HD void operator()(int i) const {
    const int slot = c.q.shadows[i];
    const LightSampleLd& ld = c.q.ld[slot];
    resolve(slot, c.integ.tracer.occluded(ld.o, ld.d, ld.tMax));
  }
  ENVGI_HD void resolve(int slot, bool blocked) const {
    const WaveQueues& q = c.q;
    q.state[slot].L += q.ldBeta[slot] * resolvedLd(q.ld[slot], blocked);
    if (!q.going[slot]) addWaveSample(q, c.sums, slot, q.state[slot].L);
  }
};

// direct where it is no one-bounce path (several light or BSDF samples, or every light of the
// collapsed map at each point): its whole estimate for the camera ray, with the shadow rays it
// traces, for each path of the camera round.
template <class I>
struct DirectSampleStage {
  WaveContext<I> c;
  ENVGI_HD void operator()(int i) const {
    const WaveQueues& q = c.q;
    const int slot = q.rayQueue(0)[i];
    uint64_t rays = 0;
    c.integ.step(&q.state[slot], q.sampler[slot], &rays);
    atomicAddRelaxed(&q.counts->rays, rays);
    addWaveSample(q, c.sums, slot, q.state[slot].L);
  }
};

// The region's pixel i's (row-major) sums of the pass added to the film.
struct FilmStage {
  FilmView film;
  WaveRegion region;
  WaveSums sums;
  ENVGI_HD void operator()(int i) const {
    const size_t p = region.filmPixel(i % region.w, i / region.w, film.width);
    if (!film.takesSamples(p)) return;
    film.sum[p] += sums.acc[i];
    if (film.sumSqLum) film.sumSqLum[p] += sums.accSq[i];
    if (film.weightSum) film.weightSum[p] += sums.accW[i];
  }
};

}  // namespace envgi
