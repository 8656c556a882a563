// A glass ball on a diffuse floor under a sky with a small sun 30 degrees from the zenith: the
// ball focuses the sun into a caustic on the floor, on the side away from the sun.
#pragma once

#include "support/TestScenes.h"

namespace envgi::test {

struct CausticSetup {
  std::unique_ptr<Scene> scene;
  Vec3f causticCentre;  // on the floor
};

inline CausticSetup causticScene(int res, bool chrome = false) {
  CausticSetup cs;
  Bsdf floor;
  floor.reflectance = Color(0.7f);
  Bsdf ball;
  ball.type = chrome ? BsdfType::Conductor : BsdfType::Dielectric;
  ball.perfectMirror = true;
  ball.ior = 1.5f;
  // The sun is one pixel of a 512x256 map (about 2e-5 sr): hard to hit by BSDF sampling
  // through glass, easy to shoot photons from.
  Image sky(512, 256);
  for (int y = 0; y < 256; ++y)
    for (int x = 0; x < 512; ++x) sky.set(x, y, Color(y < 128 ? 0.3f : 0.02f));
  sky.set(128, 44, Color(48000.f));
  Vec3f sun = EnvironmentMapView::uvToDir(Vec2f(128.5f / 512.f, 44.5f / 256.f));
  cs.causticCentre = Vec3f(0.f, 1.f, 0.f) - sun * (1.f / sun.y);
  Vec3f c = cs.causticCentre;
  auto s = sphereOnFloor(floor, ball, 6.f, std::move(sky), c + Vec3f(-3.f, 3.5f, 0.3f), c, res, 50.f);
  cs.scene = std::move(s);
  return cs;
}

// Pixels whose camera ray lands directly on the floor within [r0, r1) of the centre.
inline std::vector<int> floorPixels(const Scene& s, const EmbreeAccel& accel, Vec3f centre, float r0, float r1) {
  std::vector<int> out;
  const Camera& c = s.view().camera;
  for (int y = 0; y < c.height; ++y)
    for (int x = 0; x < c.width; ++x) {
      Ray r = c.generateRay(x + 0.5f, y + 0.5f);
      Hit h;
      if (!accel.intersect(r, &h) || h.geomId != 0) continue;
      float d = length(r.o + r.d * h.t - centre);
      if (d >= r0 && d < r1) out.push_back(y * c.width + x);
    }
  return out;
}

inline double meanLum(const Image& img, const std::vector<int>& px) {
  double s = 0.0;
  for (int i : px) s += luminance(img.at(i % img.width, i / img.width));
  return px.empty() ? 0.0 : s / double(px.size());
}

}  // namespace envgi::test
