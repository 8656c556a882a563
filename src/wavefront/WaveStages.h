// The stages of a wave of paths (WaveQueues.h), each a function of one index into its queue that
// host and device run alike: the CPU over chunks of the queue (HostStageLaunch.h), the GPU a
// thread an index (CudaStageLaunch.cuh). Camera samples → closest hits, queued as escaped rays
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

// What every stage reads: the integrator (path or direct), the camera and sample sequence, the
// film, the wave's queues and the pass's sums.
template <class I>
struct WaveContext {
  I integ;
  Camera cam;
  SampleSequence seq;
  FilmView film;
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

// Item base + i: its sampler, camera ray and filter weight into slot i, queued as a ray of the
// round of parity 0. Pixels that take no more samples (adaptive sampling) start no path.
template <class I>
struct CameraStage {
  WaveContext<I> c;
  uint64_t base;
  int s0;
  ENVGI_HD void operator()(int i) const {
    const uint64_t npix = uint64_t(c.cam.width) * uint64_t(c.cam.height), item = base + uint64_t(i);
    const uint64_t pixel = item % npix;
    if (!c.film.takesSamples(size_t(pixel))) return;
    Sampler smp = sequenceSampler(c.seq);
    float w;
    const Ray ray = startCameraSample(c.cam, smp, int(pixel % uint64_t(c.cam.width)),
                                      int(pixel / uint64_t(c.cam.width)), s0 + int(item / npix), &w);
    c.q.state[i] = c.integ.begin(ray);
    c.q.sampler[i] = smp;
    c.q.weight[i] = w;
    c.q.pixel[i] = uint32_t(pixel);
    WaveQueues::push(c.q.rayQueue(0), &c.q.counts->round.rays[0], i);
  }
};

// The round's rays traced: a miss is queued as escaped, a hit by the shade kind of its material.
template <class I>
struct ClosestHitStage {
  WaveContext<I> c;
  int parity;
  ENVGI_HD void operator()(int i) const {
    const WaveQueues& q = c.q;
    const int slot = q.rayQueue(parity)[i];
    Hit h;
    if (!c.integ.tracer.intersect(q.state[slot].ray, &h)) {
      WaveQueues::push(q.escaped, &q.counts->round.escaped, slot);
      return;
    }
    q.hit[slot] = h;
    const SceneView& sc = *c.integ.scene;
    const int kind = shadeKindOf(sc.bsdfs[sc.bsdfIndexAt(h)]);
    WaveQueues::push(q.kindQueue(kind), &q.counts->round.kinds[kind], slot);
  }
};

// An escaped ray sees the map (pathShade's escape), and its path ends.
template <class I>
struct EscapeStage {
  WaveContext<I> c;
  ENVGI_HD void operator()(int i) const {
    const WaveQueues& q = c.q;
    const int slot = q.escaped[i];
    PathState& st = q.state[slot];
    c.integ.shade(&st, false, Hit{}, q.sampler[slot], ShadowToQueue::of(q, slot), SampledParts{*c.integ.scene});
    addWaveSample(q, c.sums, slot, st.L);
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
    const WaveQueues& q = c.q;
    const int slot = q.kindQueue(Kind)[i];
    // The path and its sampler shaded where they lie: copies of them spilled on the GPU.
    PathState& st = q.state[slot];
    q.ld[slot].needsRay = false;
    using Parts = typename ShadeKindParts<Kind>::type;
    const bool going = c.integ.shade(&st, true, q.hit[slot], q.sampler[slot], ShadowToQueue::of(q, slot),
                                     Parts{{*c.integ.scene}});
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
    const WaveQueues& q = c.q;
    const int slot = q.shadows[i];
    const LightSampleLd& ld = q.ld[slot];
    const bool blocked = c.integ.tracer.occluded(ld.o, ld.d, ld.tMax);
    q.state[slot].L += q.ldBeta[slot] * resolvedLd(ld, blocked);
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

// Pixel i's sums of the pass added to the film.
struct FilmStage {
  FilmView film;
  WaveSums sums;
  ENVGI_HD void operator()(int i) const {
    if (!film.takesSamples(size_t(i))) return;
    film.sum[i] += sums.acc[i];
    if (film.sumSqLum) film.sumSqLum[i] += sums.accSq[i];
    if (film.weightSum) film.weightSum[i] += sums.accW[i];
  }
};

}  // namespace envgi
