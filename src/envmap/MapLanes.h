// The map's batch forms: where many directions meet the map, its radiance at many points, and
// many product draws placed inside their pixels, each a loop over plain arrays that the compiler
// vectorises (core/Lanes.h). Each lane's answer is the one-at-a-time function's to the bit
// (EnvironmentMapView::dirToUV, lookupUV, placeInPixel).
#pragma once

#include <vector>

#include "envmap/EnvironmentMapView.h"

namespace envgi {

struct MapLanes {
  std::vector<float> dx, dy, dz;  // findUV's directions, where a caller has none of its own
  std::vector<float> u, v;        // findUV: where each direction meets the map
  std::vector<int> picked;        // lookUp: the lanes of u, v it looks up
  std::vector<float> red, green, blue;  // lookUp and placeDraws: the radiance, by place
  // placeDraws: in, each draw's (u, v) and density in (u, v); out, the same placed inside its
  // pixel, and whether the loop left it to placeInPixel (redo).
  std::vector<float> drawU, drawV, drawPdf, placedU, placedV, placedPdf;
  std::vector<unsigned char> redo;

  void resize(size_t n);

  // Lanes [0, n): where each direction meets the map, as EnvironmentMapView::eval finds it.
  // From dx, dy, dz, or from a caller's arrays of directions.
  void setDirection(int i, Vec3f d) { dx[i] = d.x, dy[i] = d.y, dz[i] = d.z; }
  void findUV(const EnvironmentMapView& env, int n) { findUV(env, n, dx.data(), dy.data(), dz.data()); }
  void findUV(const EnvironmentMapView& env, int n, const float* x, const float* y, const float* z);
  Vec2f uvOf(int i) const { return {u[i], v[i]}; }

  // Places [0, n) of picked (lanes whose u and v findUV found): the map's radiance at each, as
  // EnvironmentMapView::lookupUV gives it there.
  void lookUp(const EnvironmentMapView& env, int n);
  Color radianceOf(int j) const { return Color(red[j], green[j], blue[j]); }

  // Lanes [0, n) of drawU, drawV, drawPdf: each draw placed inside its pixel as
  // EnvironmentMapView::placeInPixel places it, and the map's radiance there (lookupUV's).
  void setDraw(int j, Vec2f uv, float pdfUV) { drawU[j] = uv.x, drawV[j] = uv.y, drawPdf[j] = pdfUV; }
  void placeDraws(const EnvironmentMapView& env, int n);
  void placedDraw(int j, Vec2f* uv, float* pdfUV, Color* radiance) const {
    *uv = Vec2f(placedU[j], placedV[j]), *pdfUV = placedPdf[j], *radiance = radianceOf(j);
  }

 private:
  void lookUpAt(const EnvironmentMapView& env, int n, const float* us, const float* vs);
};

}  // namespace envgi
