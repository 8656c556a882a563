// The one table of names for each choice a scene file or the command line makes: integrators,
// environment strategies, samplers and pixel filters. The loader, the CLI (its help text too)
// and the tests read them; an unknown name is an error everywhere.
#pragma once

#include <stdexcept>
#include <string>

#include "envmap/EnvironmentMapView.h"
#include "sampling/Sampler.h"
#include "scene/Aov.h"
#include "scene/Camera.h"
#include "scene/IntegratorSettings.h"

namespace envgi {

template <class E>
struct Named {
  const char* name;
  E value;
  bool alias;  // accepted (Mitsuba's names) but not listed
};

template <class E, size_t N>
std::string nameList(const Named<E> (&table)[N]) {
  std::string s;
  for (const Named<E>& n : table)
    if (!n.alias) s += (s.empty() ? "" : ", ") + std::string(n.name);
  return s;
}

// Throws "unknown <what> 'name' (the list)".
template <class E, size_t N>
E findName(const Named<E> (&table)[N], const std::string& name, const char* what) {
  for (const Named<E>& n : table)
    if (name == n.name) return n.value;
  throw std::runtime_error(std::string("unknown ") + what + " '" + name + "' (" + nameList(table) + ")");
}

template <class E, size_t N>
const char* nameOf(const Named<E> (&table)[N], E value) {
  for (const Named<E>& n : table)
    if (n.value == value && !n.alias) return n.name;
  return "?";
}

inline constexpr Named<IntegratorType> kIntegratorNames[] = {
    {"path", IntegratorType::Path, false},     {"direct", IntegratorType::Direct, false},
    {"photon", IntegratorType::Photon, false}, {"sppm", IntegratorType::Sppm, false},
    {"grid", IntegratorType::Grid, false},
    {"photonmapper", IntegratorType::Photon, true},
    // Mitsuba's volumetric path tracers are its path tracer where there are no media (envgi has
    // none), and, like envgi's path, let shadow rays through masks.
    {"volpath", IntegratorType::Path, true},   {"volpathmis", IntegratorType::Path, true},
};

inline constexpr Named<SamplerType> kSamplerNames[] = {
    {"independent", SamplerType::Independent, false}, {"stratified", SamplerType::Stratified, false},
    {"sobol", SamplerType::Sobol, false},             {"multijitter", SamplerType::Stratified, true},
    {"ldsampler", SamplerType::Sobol, true},          {"orthogonal", SamplerType::Sobol, true},
};

inline constexpr Named<FilterType> kFilterNames[] = {
    {"box", FilterType::Box, false},           {"tent", FilterType::Tent, false},
    {"gaussian", FilterType::Gaussian, false}, {"mitchell", FilterType::Mitchell, false},
    {"catmullrom", FilterType::CatmullRom, false}, {"lanczos", FilterType::Lanczos, false}};

// Mitsuba's aov integrator's types (scene/Aov.h; the film's alpha is not one of them).
inline constexpr Named<AovType> kAovTypeNames[] = {
    {"albedo", AovType::Albedo, false},         {"depth", AovType::Depth, false},
    {"position", AovType::Position, false},     {"uv", AovType::Uv, false},
    {"geo_normal", AovType::GeoNormal, false},  {"sh_normal", AovType::ShNormal, false},
    {"prim_index", AovType::PrimIndex, false},  {"shape_index", AovType::ShapeIndex, false}};

inline IntegratorType findIntegrator(const std::string& name) { return findName(kIntegratorNames, name, "integrator"); }
inline const char* integratorName(IntegratorType t) { return nameOf(kIntegratorNames, t); }
inline SamplerType findSampler(const std::string& name) { return findName(kSamplerNames, name, "sampler"); }
inline const char* samplerName(SamplerType t) { return nameOf(kSamplerNames, t); }
// True where the integrator has a per-sample kernel (so runs on the GPU too).
inline bool hasSampleKernel(IntegratorType t) { return t == IntegratorType::Path || t == IntegratorType::Direct; }

struct StrategyName {
  const char* name;
  EnvStrategy env;     // how light samples draw the map
  int emitterSamples;  // direct's defaults
  int bsdfSamples;
  bool mapOnly;        // a map strategy in its own right (envmap samples/plot accept it)
};

// mis is the paper's Eq. 3-6: Algorithm 1's CDFs (binary search) for the light sample beside a
// BSDF sample, so that importance against mis changes one thing; alias draws the same density
// through an alias table (1.45x faster in bench_envmap). bsdf never draws the map (its table
// entry is unused). product (the default) multiplies the density by a cosine bound about the
// normal (envmap/CosineProduct.h); points is the collapsed map at every point, points-draw
// one of its lights a sample.
inline constexpr StrategyName kStrategyNames[] = {
    {"uniform", EnvStrategy::Uniform, 1, 0, true},       {"cosine", EnvStrategy::Cosine, 1, 0, true},
    {"importance", EnvStrategy::Algorithm1, 1, 0, true}, {"alias", EnvStrategy::Alias, 1, 0, true},
    {"importance-bilinear", EnvStrategy::Importance, 1, 0, true},
    {"adaptive", EnvStrategy::Adaptive, 1, 0, true},     {"bsdf", EnvStrategy::Alias, 0, 1, false},
    {"mis", EnvStrategy::Algorithm1, 1, 1, false},       {"points", EnvStrategy::PointsAll, 1, 0, false},
    {"product", EnvStrategy::Product, 1, 1, true},       {"points-draw", EnvStrategy::Points, 1, 0, false},
};

inline std::string strategyNameList(bool mapOnly = false) {
  std::string s;
  for (const StrategyName& n : kStrategyNames)
    if (!mapOnly || n.mapOnly) s += (s.empty() ? "" : ", ") + std::string(n.name);
  return s;
}

// Throws for a name not in the table (or not a map strategy, when mapOnly).
inline const StrategyName& findStrategy(const std::string& name, bool mapOnly = false) {
  for (const StrategyName& n : kStrategyNames)
    if (name == n.name && (!mapOnly || n.mapOnly)) return n;
  throw std::runtime_error("unknown strategy '" + name + "' (" + strategyNameList(mapOnly) + ")");
}

}  // namespace envgi
