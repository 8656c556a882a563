// Light probes in the layouts of Debevec's Light Probe Image Gallery (the paper's reference
// [17]), resampled to the lat-long maps the renderer reads. Each layout is read in the probe's
// own frame: forward -Z, up +Y, right +X.
//
// The disk layouts put forward at the image centre and backward on the rim; a direction at
// angle theta from forward lands at radius rho(theta) on the unit disk, along its (x, y):
//   angular map (Debevec's gallery, +X on the right):  rho = theta / pi
//   mirror ball (a photograph of a chrome ball, taken looking along +Z, whose centre reflects
//   -Z back at the camera): rho = sin(theta / 2), and the ball mirrors left and right: +X is
//   on the image's left, where the camera's own left is (Blender's mirror-ball projection too)
// The cube crosses hold six 90-degree views from the centre, N x N each:
//   vertical cross (3N x 4N, the gallery's): up / left, forward, right / down / backward, the
//   backward face upside down below the downward one;
//   horizontal cross (4N x 3N): up / left, forward, right, backward / down, every side face
//   upright.
// The lat-long map made from a probe has the forward direction in its centre column, as
// HDRShop's and OpenImageIO's conversions do; with envgi's (Mitsuba's) lat-long convention the
// centre column faces +Z, so the probe's frame is the map's turned 180 degrees about +Y.
#pragma once

#include <string>

#include "core/Vec.h"
#include "image/Image.h"

namespace envgi {

// Cross: a cube cross, vertical (3N x 4N) or horizontal (4N x 3N), told apart by its shape.
enum class ProbeLayout { Angular, MirrorBall, Cross };

// "angular", "mirrorball" or "cross"; throws std::runtime_error naming the accepted ones otherwise.
ProbeLayout parseProbeLayout(const std::string& name);
const char* probeLayoutName(ProbeLayout layout);

// Where unit direction d of the probe's frame lands on a disk layout (Angular, MirrorBall), x
// right, y up, |p| <= 1.
Vec2f probeDiskPoint(ProbeLayout layout, Vec3f d);
// The inverse on the disk: the unit direction that lands on p (|p| <= 1).
Vec3f probeDiskDirection(ProbeLayout layout, Vec2f p);

// A cube face and where on it, (s, t) in [-1, 1]^2 (s to the face's right, t up as the cross
// shows it): faces +X, -X, +Y, -Y, +Z, -Z are 0 to 5. `upright` asks for the backward face (+Z)
// as the horizontal cross holds it; otherwise it is upside down, as in the vertical cross.
struct CubeFacePoint {
  int face;
  Vec2f st;
};
CubeFacePoint cubeFacePoint(Vec3f d, bool upright);
// The inverse: the unit direction through (s, t) of a face.
Vec3f cubeFaceDirection(int face, Vec2f st, bool upright);
// The cell (column, row) of a face in the cross.
void crossCell(int face, bool vertical, int* column, int* row);

// A lat-long map direction (envgi's convention, EnvironmentMapView::uvToDir) in the probe's frame.
inline Vec3f latLongToProbeFrame(Vec3f mapDir) { return {-mapDir.x, mapDir.y, -mapDir.z}; }

constexpr int kMaxProbeMapWidth = 32768;     // a 32768 x 16384 map: 6 GB of floats
constexpr int kMaxProbeSamplesPerSide = 64;

struct ProbeConversion {
  int width = 0;           // of the lat-long map (height = width / 2); 0: twice a disk's width,
                           // four times a cube face's
  int samplesPerSide = 0;  // n x n bilinear lookups averaged per map pixel; 0: enough that each
                           // covers at most one probe pixel
};

// Resamples a probe image to a lat-long map. Throws std::runtime_error for an image whose shape
// is not the layout's (square of at least 2 x 2 for the disks; 3N x 4N or 4N x 3N for a cross),
// a width that is odd or outside [2, kMaxProbeMapWidth],
// or more than kMaxProbeSamplesPerSide lookups a side; NaN, infinite and
// negative values count as black (EnvironmentMap warns about them the same way), and *invalid,
// where given, receives how many there were.
Image probeToLatLong(const Image& probe, ProbeLayout layout, const ProbeConversion& opts = {},
                     size_t* invalid = nullptr);

}  // namespace envgi
