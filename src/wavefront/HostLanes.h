// What the CPU's batch forms of the wave stages (HostStages.h) keep beside a wave's queues, one
// per CPU thread, allocated once and never per ray: by slot, each path's hit answer and its parts
// worked out before it is shaded; lists of slots for the stage at hand; and the round's work
// done lane by lane (its samples, the map's lookups and draws, its materials' BSDFs).
#pragma once

#include <vector>

#include "envmap/MapLanes.h"
#include "materials/RoughConductorLanes.h"
#include "materials/RoughPlasticLanes.h"
#include "wavefront/PreparedHit.h"
#include "wavefront/SampleLanes.h"

namespace envgi {

struct HostLanes {
  // By slot.
  std::vector<unsigned char> found, blocked;
  std::vector<PreparedHit> prepared;      // each hit's parts, worked out before it is shaded
  std::vector<ProductDescent> descent;  // each hit's product draw, taken level by level
  // Lists of slots: the lanes' paths (laneSlot), a kind's hits with a product draw, and the
  // material lanes' scratch (MaterialLanes.h).
  std::vector<int> laneSlot, productDraws, sampling, picking;
  SampleLanes lanes;
  MapLanes map;
  RoughPlasticLanes roughPlastic;
  RoughConductorLanes roughConductor;
  // The wave's sample before its pixels are set, and whether its draws are made in lanes (the
  // camera stage's batch form sets them for the stages after it).
  Sampler first;
  bool inLanes = false;

  void resize(size_t n) {
    if (found.size() >= n) return;
    found.resize(n), blocked.resize(n), prepared.resize(n), descent.resize(n);
    for (std::vector<int>* q : {&laneSlot, &productDraws, &sampling, &picking}) q->resize(n);
    lanes.resize(n), map.resize(n), roughPlastic.resize(n), roughConductor.resize(n);
  }
};

}  // namespace envgi
