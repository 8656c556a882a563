// A render pass of path or direct through the wave stages (WaveStages.h), for any device: a
// Launch runs a stage over the indices [0, n) that are below *count (all of them where count is
// null), and moves a value to or from the queues' memory (write, read). The host decides how
// many rounds a wave takes from the counts it reads back after each round; every stage of a
// round is sized by the round's rays, and a queue's own count (on the device) bounds its stage.
#pragma once

#include <algorithm>
#include <utility>

#include "wavefront/WaveStages.h"

namespace envgi {

// The shade kinds a scene's hits need a stage for: the kind (shadeKindOf) of each shape's
// material. A blend's members are shaded in the blend's stage, so they launch none of their own.
struct ShadeKindSet {
  bool used[kShadeKinds] = {};
  static ShadeKindSet of(const SceneView& sc) {
    ShadeKindSet s;
    for (int i = 0; i < sc.meshCount; ++i) s.used[shadeKindOf(sc.bsdfs[sc.meshes[i].bsdf])] = true;
    for (int i = 0; i < sc.sphereCount; ++i) s.used[shadeKindOf(sc.bsdfs[sc.spheres[i].bsdf])] = true;
    return s;
  }
  static ShadeKindSet all() {
    ShadeKindSet s;
    for (bool& u : s.used) u = true;
    return s;
  }
};

namespace detail {
template <class I, class Launch, int... K>
void shadeEachKind(Launch& launch, const WaveContext<I>& c, const ShadeKindSet& kinds, int parity, int live,
                   std::integer_sequence<int, K...>) {
  ((kinds.used[K] ? launch(ShadeStage<I, K>{c, parity}, live, &c.q.counts->round.kinds[K]) : void()), ...);
}
}  // namespace detail

// Samples [s0, s1) of every pixel that takes samples, added to c.film; the rays traced and the
// samples dropped are added to *counters.
template <class I, class Launch>
void runWavePass(Launch& launch, const WaveContext<I>& c, const ShadeKindSet& kinds, int s0, int s1,
                 PixelCounters* counters) {
  const uint64_t npix = c.region.pixels(), total = npix * uint64_t(s1 - s0);
  launch.zero(c.sums.acc, npix * sizeof(Color));
  launch.zero(c.sums.accSq, npix * sizeof(double));
  launch.zero(c.sums.accW, npix * sizeof(float));
  launch.write(&c.q.counts->dropped, 0u);
  launch.write(&c.q.counts->rays, uint64_t(0));
  const uint64_t waveSize = std::min<uint64_t>(uint64_t(c.q.capacity), npix);
  for (uint64_t base = 0; base < total; base += waveSize) {
    launch.write(&c.q.counts->round, WaveRound{});
    launch(CameraStage<I>{c, base, s0}, int(std::min(waveSize, total - base)), nullptr);
    WaveRound r = launch.read(&c.q.counts->round);
    if (!c.integ.shadesAfterTrace()) {
      launch(DirectSampleStage<I>{c}, r.rays[0], nullptr);
      continue;
    }
    for (int parity = 0, round = 0; r.rays[parity] > 0; parity ^= 1, ++round) {
      const int live = r.rays[parity];
      counters->rays += uint64_t(live);
      WaveRound next{};
      next.rays[parity] = live;
      launch.write(&c.q.counts->round, next);
      launch(ClosestHitStage<I>{c, parity, round == 0}, live, nullptr);
      launch(EscapeStage<I>{c, round == 0}, live, &c.q.counts->round.escaped);
      detail::shadeEachKind(launch, c, kinds, parity, live, std::make_integer_sequence<int, kShadeKinds>{});
      launch(ShadowStage<I>{c}, live, &c.q.counts->round.shadows);
      r = launch.read(&c.q.counts->round);
      counters->rays += uint64_t(r.shadows);
    }
  }
  launch(FilmStage{c.film, c.region, c.sums}, int(npix), nullptr);
  counters->dropped += launch.read(&c.q.counts->dropped);
  counters->rays += launch.read(&c.q.counts->rays);
}

}  // namespace envgi
