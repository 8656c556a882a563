// Turns a scene's camera to face its largest mesh from a distance that fits it in view: lets a
// mesh of any size (the dragon) stand in for the Buddha in buddha.xml.
#pragma once

#include "scene/Scene.h"

namespace envgi::test {

inline void frameLargestMesh(Scene& scene) {
  const TriangleMesh* big = &scene.meshes.at(0);
  for (const TriangleMesh& m : scene.meshes)
    if (m.triangleCount() > big->triangleCount()) big = &m;
  Vec3f lo(INFINITY), hi(-INFINITY);
  for (Vec3f p : big->positions) {
    lo = vmin(lo, p);
    hi = vmax(hi, p);
  }
  Vec3f c = (lo + hi) * 0.5f;
  scene.camera.toWorld = lookAt(c + Vec3f(0.f, 0.3f, 1.2f) * length(hi - lo), c, Vec3f(0, 1, 0));
}

}  // namespace envgi::test
