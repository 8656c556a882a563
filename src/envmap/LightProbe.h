// Light probes in the two square layouts of Debevec's Light Probe Image Gallery (the paper's
// reference [17]), resampled to the lat-long maps the renderer reads.
//
// Both layouts put the probe's forward direction (-Z in its frame, +Y up) at the image centre
// and the backward one on the rim; a direction at angle theta from forward lands at radius
// rho(theta) on the unit disk, along its (x, y) component:
//   angular map (Debevec's gallery, +X on the right):  rho = theta / pi
//   mirror ball (a photograph of a chrome ball, taken looking along +Z, whose centre reflects
//   -Z back at the camera): rho = sin(theta / 2), and the ball mirrors left and right: +X is
//   on the image's left, where the camera's own left is (Blender's mirror-ball projection too)
// The lat-long map made from a probe has the forward direction in its centre column, as
// HDRShop's and OpenImageIO's conversions do; with envgi's (Mitsuba's) lat-long convention the
// centre column faces +Z, so the probe's frame is the map's turned 180 degrees about +Y.
#pragma once

#include <string>

#include "core/Vec.h"
#include "image/Image.h"

namespace envgi {

enum class ProbeLayout { Angular, MirrorBall };

// "angular" or "mirrorball"; throws std::runtime_error naming the accepted ones otherwise.
ProbeLayout parseProbeLayout(const std::string& name);

// Where unit direction d of the probe's frame lands on the probe's disk, x right, y up, |p| <= 1.
Vec2f probeDiskPoint(ProbeLayout layout, Vec3f d);
// The inverse on the disk: the unit direction that lands on p (|p| <= 1).
Vec3f probeDiskDirection(ProbeLayout layout, Vec2f p);

// A lat-long map direction (envgi's convention, EnvironmentMapView::uvToDir) in the probe's frame.
inline Vec3f latLongToProbeFrame(Vec3f mapDir) { return {-mapDir.x, mapDir.y, -mapDir.z}; }

constexpr int kMaxProbeMapWidth = 32768;     // a 32768 x 16384 map: 6 GB of floats
constexpr int kMaxProbeSamplesPerSide = 64;

struct ProbeConversion {
  int width = 0;           // of the lat-long map (height = width / 2); 0: twice the probe's width
  int samplesPerSide = 0;  // n x n bilinear lookups averaged per map pixel; 0: enough that each
                           // covers at most one probe pixel
};

// Resamples a square probe image to a lat-long map. Throws std::runtime_error for an image that
// is not square or smaller than 2 x 2, a width that is odd or outside [2, kMaxProbeMapWidth],
// or more than kMaxProbeSamplesPerSide lookups a side; NaN, infinite and
// negative values count as black (EnvironmentMap warns about them the same way), and *invalid,
// where given, receives how many there were.
Image probeToLatLong(const Image& probe, ProbeLayout layout, const ProbeConversion& opts = {},
                     size_t* invalid = nullptr);

}  // namespace envgi
