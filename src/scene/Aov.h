// Arbitrary output variables, as Mitsuba 3's `aov` integrator names them: what the camera's
// first hit is (its distance, position, normals, (u, v), material's albedo, indices), written as
// extra channels beside the image, for compositing and for denoisers that take albedo and normals.
#pragma once

#include <string>
#include <vector>

namespace envgi {

// Alpha is not in Mitsuba's list: it is the film's A channel (hdrfilm's pixel_format rgba).
enum class AovType { Albedo, Depth, Position, Uv, GeoNormal, ShNormal, PrimIndex, ShapeIndex, Alpha };

struct Aov {
  std::string name;  // the channels' prefix: name.R, name.G, ...
  AovType type = AovType::Depth;
};

// Mitsuba's "name:type,name:type" list (types albedo, depth, position, uv, geo_normal,
// sh_normal, prim_index, shape_index); throws std::runtime_error naming what is wrong.
std::vector<Aov> parseAovs(const std::string& spec);

// The EXR channels an AOV fills, in order: albedo name.R/G/B, depth name.T, position and the
// normals name.X/Y/Z, uv name.U/V, the indices name.I (Mitsuba's suffixes); alpha is "A".
std::vector<std::string> aovChannelNames(const Aov& aov);

}  // namespace envgi
