// Mitsuba's perspective, thin-lens and orthographic sensors: look along +z of their frame, +y
// up; to_world places them (and scales an orthographic camera's view).
#pragma once

#include "core/Transform.h"
#include "sampling/Warp.h"
#include "scene/Ray.h"
#include "scene/ReconstructionFilter.h"

namespace envgi {

struct Camera {
  Transform toWorld;
  int width = 512, height = 512;
  // Half extent of the image plane at distance 1; for an orthographic camera, of its near plane
  // in camera space (Mitsuba's [-1, 1] x [-1/aspect, 1/aspect], which to_world's scale resizes).
  float tanHalfX = 0.f, tanHalfY = 0.f;
  float nearClip = 1e-2f, farClip = 1e4f;
  ReconstructionFilter filter;  // Mitsuba's default: gaussian, stddev 0.5
  // Thin lens (Mitsuba's `thinlens`); a pinhole when the radius is 0.
  float apertureRadius = 0.f, focusDistance = 1e4f;
  // Mitsuba's `orthographic`: parallel rays along the frame's +z from points of the near plane.
  bool orthographic = false;
  // Mitsuba's crop window: the image is width x height pixels of a film of filmWidth x
  // filmHeight, from its pixel (cropX, cropY); a film of 0 x 0 is the image itself.
  int filmWidth = 0, filmHeight = 0, cropX = 0, cropY = 0;

  ENVGI_HD float fullWidth() const { return float(filmWidth > 0 ? filmWidth : width); }
  ENVGI_HD float fullHeight() const { return float(filmHeight > 0 ? filmHeight : height); }

  // Whether a camera sample needs a point on the lens (a 2D draw after the filter's).
  ENVGI_HD bool hasLens() const { return apertureRadius > 0.f; }

  // A ray through image position (x, y) in pixels, (0,0) the top-left corner of the image (of
  // the crop window, where there is one);
  // `lens` picks the point on the aperture (unused for a pinhole).
  ENVGI_HD Ray generateRay(float x, float y, Vec2f lens = Vec2f(0.5f, 0.5f)) const {
    // On the plane z = 1: its length is 1 / cos of the angle to the axis, which turns the
    // near and far planes into distances along the ray without normalising twice.
    const Vec3f d = imagePlanePoint(x, y);
    Ray r;
    if (orthographic) {
      // As Mitsuba's: the ray's length is far - near in world units, whatever to_world's scale.
      r.o = toWorld.point(Vec3f(d.x, d.y, nearClip));
      r.d = normalize(toWorld.vector(Vec3f(0.f, 0.f, 1.f)));
      r.tMax = farClip - nearClip;
      return r;
    }
    if (hasLens()) {
      // Every ray through the pixel's point on the plane in focus, from a point of the lens.
      Vec2f a = sampleConcentricDisk(lens) * apertureRadius;
      Vec3f dir = d * focusDistance - Vec3f(a.x, a.y, 0.f);
      float invZ = length(dir) / dir.z;  // 1 / cos of dir's angle to the axis
      r.d = normalize(toWorld.vector(dir));
      r.o = toWorld.point(Vec3f(a.x, a.y, 0.f)) + r.d * (nearClip * invZ);
      r.tMax = (farClip - nearClip) * invZ;
      return r;
    }
    return pinholeRay(d);
  }

  // generateRay's pinhole, through the point d of the plane z = 1 (camera space).
  ENVGI_HD Ray pinholeRay(Vec3f d) const {
    Ray r;
    float len = length(d);
    r.d = normalize(toWorld.vector(d));
    r.o = toWorld.translation() + r.d * (nearClip * len);
    r.tMax = (farClip - nearClip) * len;
    return r;
  }
  // The point of the plane z = 1 (camera space) that image position (x, y) looks through.
  ENVGI_HD Vec3f imagePlanePoint(float x, float y) const {
    float sx = 2.f * (x + float(cropX)) / fullWidth() - 1.f, sy = 1.f - 2.f * (y + float(cropY)) / fullHeight();
    // Camera-space +x is the image's left (lookat builds x = up x dir), so image right is -x.
    return {-sx * tanHalfX, sy * tanHalfY, 1.f};
  }
};

// Film position (pixels) of a world point, the inverse of generateRay; false behind the camera.
ENVGI_INLINE bool projectToFilm(const Camera& c, Vec3f p, float* x, float* y) {
  Vec3f q = c.toWorld.inversePoint(p);
  if (c.orthographic ? !(q.z >= c.nearClip) : q.z <= 0.f) return false;
  float w = c.orthographic ? 1.f : q.z;
  float sx = -(q.x / w) / c.tanHalfX, sy = (q.y / w) / c.tanHalfY;
  *x = 0.5f * (sx + 1.f) * c.fullWidth() - float(c.cropX);
  *y = 0.5f * (1.f - sy) * c.fullHeight() - float(c.cropY);
  return *x >= 0.f && *y >= 0.f && *x < float(c.width) && *y < float(c.height);
}

// A camera ray for pixel (x, y) from a sampler's next draws: the filter's offset, then the
// point on the lens, which a pinhole does not draw (so its sequence stays as it was). *weight
// is the sample's filter weight, which multiplies its radiance in the film: one except for
// the filters with negative lobes (ReconstructionFilter.h).
template <class Smp>
ENVGI_HD Ray sampleCameraRay(const Camera& cam, Smp& smp, int x, int y, float* weight) {
  FilterSample fs = sampleFilter(cam.filter, smp.get2D());
  *weight = fs.weight;
  Vec2f lens = cam.hasLens() ? smp.get2D() : Vec2f(0.5f, 0.5f);
  return cam.generateRay(float(x) + 0.5f + fs.offset.x, float(y) + 0.5f + fs.offset.y, lens);
}

}  // namespace envgi
