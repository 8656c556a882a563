#include "scene/MitsubaPlugins.h"

#include <algorithm>
#include <initializer_list>

namespace envgi {

namespace {

struct PluginProperties {
  std::string_view kind;
  std::initializer_list<std::string_view> types;  // empty: every type of the kind (a base class)
  std::initializer_list<std::string_view> names;
};

// From Mitsuba 3's sources: the plugins' parameter tables and the properties their base classes
// read. Only plugins envgi reads (or a scene written for Mitsuba may hold) are listed.
const PluginProperties kMitsuba[] = {
    // Shape and Mesh
    {"shape", {}, {"to_world", "flip_normals", "silhouette_sampling_weight"}},
    {"shape", {"ply", "obj", "serialized"}, {"filename", "face_normals", "flip_tex_coords"}},
    {"shape", {"serialized"}, {"shape_index"}},
    {"shape", {"sphere"}, {"center", "radius"}},
    {"shape", {"cylinder"}, {"p0", "p1", "radius"}},
    // Emitter and Endpoint
    {"emitter", {}, {"to_world", "sampling_weight"}},
    {"emitter", {"envmap"}, {"filename", "bitmap", "data", "scale", "mis_compensation"}},
    {"emitter", {"constant", "area", "directionalarea"}, {"radiance"}},
    {"emitter", {"point"}, {"intensity", "position"}},
    {"emitter", {"spot"}, {"intensity", "cutoff_angle", "beam_width", "texture"}},
    {"emitter", {"directional"}, {"irradiance", "direction"}},
    {"emitter", {"projector"}, {"irradiance", "scale", "fov", "fov_axis", "focal_length"}},
    {"emitter",
     {"sunsky", "timed_sunsky"},
     {"albedo", "complex_sun", "latitude", "longitude", "timezone", "turbidity", "sky_scale", "sun_scale",
      "sun_aperture", "sun_direction", "year", "month", "day", "hour", "minute", "second", "start_year", "start_month",
      "start_day", "end_year", "end_month", "end_day", "window_start_time", "window_end_time", "shutter_open",
      "shutter_close"}},
    // Sensor and ProjectiveCamera
    {"sensor",
     {},
     {"to_world", "near_clip", "far_clip", "shutter_open", "shutter_close", "srf", "fov", "fov_axis", "focal_length",
      "focus_distance", "x_fov", "principal_point_offset_x", "principal_point_offset_y"}},
    {"sensor", {"thinlens"}, {"aperture_radius"}},
    // Film
    {"film",
     {},
     {"width", "height", "crop_offset_x", "crop_offset_y", "crop_width", "crop_height", "sample_border",
      "file_format", "pixel_format", "component_format", "compensate", "banner", "high_quality_edges"}},
    {"rfilter", {"gaussian"}, {"stddev"}},
    {"rfilter", {"tent"}, {"radius"}},
    {"rfilter", {"lanczos"}, {"lobes"}},
    {"rfilter", {"mitchell"}, {"B", "C"}},
    // Sampler
    {"sampler", {}, {"sample_count", "seed"}},
    {"sampler", {"stratified", "multijitter", "orthogonal"}, {"jitter"}},
    {"sampler", {"orthogonal"}, {"strength"}},
    // Integrator
    {"integrator", {}, {"max_depth", "rr_depth", "hide_emitters", "timeout", "samples_per_pass", "block_size"}},
    {"integrator", {"direct"}, {"shading_samples", "emitter_samples", "bsdf_samples"}},
    {"integrator", {"aov"}, {"aovs"}},
    // BSDFs
    {"bsdf", {"diffuse"}, {"reflectance"}},
    {"bsdf",
     {"dielectric", "thindielectric", "roughdielectric"},
     {"int_ior", "ext_ior", "eta", "specular_reflectance", "specular_transmittance"}},
    {"bsdf", {"conductor", "roughconductor"}, {"material", "eta", "k", "specular_reflectance"}},
    {"bsdf", {"plastic", "roughplastic"}, {"int_ior", "ext_ior", "eta", "specular_reflectance", "diffuse_reflectance", "nonlinear"}},
    {"bsdf", {"roughconductor", "roughdielectric"}, {"distribution", "alpha", "alpha_u", "alpha_v", "sample_visible"}},
    {"bsdf", {"roughplastic"}, {"distribution", "alpha", "sample_visible"}},
    {"bsdf",
     {"principled"},
     {"base_color", "roughness", "anisotropic", "metallic", "spec_trans", "eta", "specular", "spec_tint", "sheen",
      "sheen_tint", "flatness", "clearcoat", "clearcoat_gloss", "main_specular_sampling_rate", "clearcoat_sampling_rate",
      "diffuse_reflectance_sampling_rate"}},
    {"bsdf", {"mask"}, {"opacity"}},
    {"bsdf", {"blendbsdf"}, {"weight"}},
    {"bsdf", {"normalmap", "bumpmap"}, {"flip_invalid_normals", "use_shadowing_function"}},
    {"bsdf", {"bumpmap"}, {"scale"}},
    // Textures
    {"texture",
     {"bitmap"},
     {"filename", "bitmap", "data", "filter_type", "wrap_mode", "raw", "to_uv", "accel", "format"}},
    {"texture", {"checkerboard"}, {"color0", "color1", "to_uv"}},
};

bool covers(const PluginProperties& p, std::string_view kind, std::string_view type) {
  return p.kind == kind && (p.types.size() == 0 || std::find(p.types.begin(), p.types.end(), type) != p.types.end());
}

size_t editDistance(std::string_view a, std::string_view b) {
  std::vector<size_t> row(b.size() + 1);
  for (size_t j = 0; j <= b.size(); ++j) row[j] = j;
  for (size_t i = 1; i <= a.size(); ++i) {
    size_t diag = row[0];
    row[0] = i;
    for (size_t j = 1; j <= b.size(); ++j) {
      size_t up = row[j];
      row[j] = std::min({row[j] + 1, row[j - 1] + 1, diag + (a[i - 1] == b[j - 1] ? 0 : 1)});
      diag = up;
    }
  }
  return row[b.size()];
}

}  // namespace

bool mitsubaPluginTakes(std::string_view kind, std::string_view type, std::string_view name) {
  for (const PluginProperties& p : kMitsuba)
    if (covers(p, kind, type) && std::find(p.names.begin(), p.names.end(), name) != p.names.end()) return true;
  return false;
}

std::vector<std::string> mitsubaPluginProperties(std::string_view kind, std::string_view type) {
  std::vector<std::string> out;
  for (const PluginProperties& p : kMitsuba)
    if (covers(p, kind, type))
      for (std::string_view n : p.names) out.emplace_back(n);
  return out;
}

std::string nearestName(std::string_view name, const std::vector<std::string>& candidates) {
  std::string best;
  size_t bestDistance = 3;
  for (const std::string& c : candidates) {
    size_t d = editDistance(name, c);
    if (d > 0 && d < bestDistance && 2 * d < std::max(name.size(), c.size())) best = c, bestDistance = d;
  }
  return best;
}

std::string didYouMean(std::string_view name, const std::vector<std::string>& candidates, std::string_view open,
                       std::string_view close) {
  std::string near = nearestName(name, candidates);
  return near.empty() ? "" : " (did you mean " + std::string(open) + near + std::string(close) + "?)";
}

}  // namespace envgi
