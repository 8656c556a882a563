// A tile wavefront's room, one per CPU thread, allocated once and never per ray: a slot per
// pixel of the tile for its path, and the queues of path slots that the stages hand on
// (TileStages.h). A queue is an array of slot indices and its length, kept by the stage that
// fills it.
#pragma once

#include <vector>

#include "envmap/MapLanes.h"
#include "materials/RoughConductorLanes.h"
#include "materials/RoughPlasticLanes.h"
#include "wavefront/PreparedHit.h"
#include "wavefront/SampleLanes.h"

namespace envgi {

struct TileQueues {
  // A slot per pixel of the tile (its row-major index in the tile).
  std::vector<PathState> state;
  std::vector<Sampler> sampler;
  std::vector<Hit> hit;
  std::vector<unsigned char> found, going, blocked;
  std::vector<LightSampleLd> ld;  // each path's next-event sample of this round
  std::vector<Color> ldBeta;      // and the path's beta when it was drawn
  std::vector<float> weight;      // each path's filter weight
  std::vector<Color> acc;         // each pixel's sums over the tile's samples
  std::vector<double> accSq;
  std::vector<float> accW;
  std::vector<PreparedHit> prepared;      // each path's parts, worked out before it is shaded
  std::vector<ProductDescent> descent;  // each hit's product draw, taken level by level

  // The queues, of slots: the round's live paths, those whose ray escaped, those whose ray hit,
  // the hits with a product draw, the paths whose light sample has a shadow ray; and the
  // material lanes' scratch (MaterialLanes.h).
  std::vector<int> live, escaped, hits, productDraws, shadowRays;
  std::vector<int> sampling, picking;
  // The round's work done lane by lane: its samples, its rays' and draws' meetings with the
  // map, and its materials' BSDFs, by kind.
  SampleLanes lanes;
  MapLanes map;
  RoughPlasticLanes roughPlastic;
  RoughConductorLanes roughConductor;

  void resize(size_t n) {
    if (state.size() >= n) return;
    state.resize(n), sampler.resize(n), hit.resize(n), found.resize(n), going.resize(n), blocked.resize(n);
    ld.resize(n), ldBeta.resize(n), weight.resize(n), acc.resize(n), accSq.resize(n), accW.resize(n);
    prepared.resize(n), descent.resize(n);
    for (std::vector<int>* q : {&live, &escaped, &hits, &productDraws, &shadowRays, &sampling, &picking}) q->resize(n);
    lanes.resize(n), map.resize(n), roughPlastic.resize(n), roughConductor.resize(n);
  }
};

}  // namespace envgi
