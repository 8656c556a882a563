#include "scene/IntegratorSettings.h"

#include <algorithm>

#include "envmap/CollapsedMap.h"
#include "scene/NameTables.h"

namespace envgi {

EnvSamplingSettings EnvSamplingSettings::fromProperties(Properties& p) {
  EnvSamplingSettings s;
  s.strategy = p.getString("strategy", s.strategy);
  s.pointCount = p.getInt("point_count", s.pointCount);
  s.pointMethod = p.getString("point_method", s.pointMethod);
  try {
    findStrategy(s.strategy);
  } catch (const std::runtime_error& e) {
    p.fail(e.what());
  }
  if (s.pointCount < 1 || s.pointCount > kMaxCollapsedPoints)
    p.fail("point_count must be between 1 and " + std::to_string(kMaxCollapsedPoints));
  if (s.pointMethod != "sample" && s.pointMethod != "mediancut")
    p.fail("unknown point_method '" + s.pointMethod + "' (sample, mediancut)");
  return s;
}

static int readMaxDepth(Properties& p, int def) {
  int d = p.getInt("max_depth", def);
  if (d < -1 || d == 0) p.fail("max_depth must be -1 or at least 1");
  return d;
}

// The photon integrators' loops run to a depth: -1 reads as kUnboundedChainDepth (it had
// stopped every photon and camera chain before its first bounce: a black image).
static int chainDepth(int maxDepth) { return maxDepth < 0 ? kUnboundedChainDepth : maxDepth; }

// The path-length and emitter properties that path and photon share (Mitsuba's names); the
// pointers hold the defaults on entry.
static void readPathProperties(Properties& p, int* maxDepth, int* rrDepth, bool* hideEmitters) {
  *maxDepth = readMaxDepth(p, *maxDepth);
  *rrDepth = p.getInt("rr_depth", *rrDepth);
  *hideEmitters = p.getBool("hide_emitters", *hideEmitters);
  if (*rrDepth < 1) p.fail("rr_depth must be at least 1");
}

PathSettings PathSettings::fromProperties(Properties& p) {
  PathSettings s;
  readPathProperties(p, &s.maxDepth, &s.rrDepth, &s.hideEmitters);
  return s;
}

DirectSettings DirectSettings::fromProperties(Properties& p) {
  DirectSettings s;
  int shading = p.getInt("shading_samples", -1);
  s.emitterSamples = p.getInt("emitter_samples", shading);
  s.bsdfSamples = p.getInt("bsdf_samples", shading);
  s.hideEmitters = p.getBool("hide_emitters", s.hideEmitters);
  s.misHeuristic = p.getString("mis_heuristic", s.misHeuristic);
  if (s.misHeuristic != "power" && s.misHeuristic != "balance") p.fail("mis_heuristic must be power or balance");
  if (s.emitterSamples < -1 || s.bsdfSamples < -1) p.fail("sample counts must not be negative");
  return s;
}

PhotonSettings PhotonSettings::fromProperties(Properties& p) {
  PhotonSettings s;
  readPathProperties(p, &s.maxDepth, &s.rrDepth, &s.hideEmitters);
  s.maxDepth = chainDepth(s.maxDepth);
  int g = p.getInt("global_photons", int(s.globalPhotons)), c = p.getInt("caustic_photons", int(s.causticPhotons));
  if (g < 0 || c < 0) p.fail("photon counts must not be negative");
  s.globalPhotons = size_t(g);
  s.causticPhotons = size_t(c);
  s.lookupSize = p.getInt("lookup_size", s.lookupSize);
  if (s.lookupSize < 1 || s.lookupSize > kMaxPhotonLookup)
    p.fail("lookup_size must be between 1 and " + std::to_string(kMaxPhotonLookup));
  s.maxRadius = p.getFloat("max_radius", s.maxRadius);
  s.gatherSamples = p.getInt("gather_samples", s.gatherSamples);
  s.coneFilter = p.getBool("cone_filter", s.coneFilter);
  if (s.maxRadius < 0.f || s.gatherSamples < 0) p.fail("max_radius and gather_samples must not be negative");
  return s;
}

SppmSettings SppmSettings::fromProperties(Properties& p) {
  SppmSettings s;
  s.maxDepth = chainDepth(readMaxDepth(p, s.maxDepth));
  s.passes = p.getInt("passes", s.passes);
  int pc = p.getInt("photon_count", int(s.photonCount));
  s.initialRadius = p.getFloat("initial_radius", s.initialRadius);
  s.alpha = p.getFloat("alpha", s.alpha);
  if (s.passes < 1 || pc < 1) p.fail("passes and photon_count must be positive");
  if (!(s.alpha > 0.f && s.alpha < 1.f)) p.fail("alpha must be in (0, 1)");
  if (s.initialRadius < 0.f) p.fail("initial_radius must not be negative");
  s.photonCount = size_t(pc);
  return s;
}

GridSettings GridSettings::fromProperties(Properties& p) {
  GridSettings s;
  readPathProperties(p, &s.maxDepth, &s.rrDepth, &s.hideEmitters);
  s.maxDepth = chainDepth(s.maxDepth);
  s.resolution = p.getInt("resolution", s.resolution);
  s.gatherRays = p.getInt("gather_rays", s.gatherRays);
  s.refineRays = p.getInt("refine_rays", s.refineRays);
  s.maxGatherRays = p.getInt("max_gather_rays", std::max(s.maxGatherRays, s.gatherRays));
  int g = p.getInt("global_photons", int(s.globalPhotons)), c = p.getInt("caustic_photons", int(s.causticPhotons));
  s.basis = p.getString("basis", s.basis);
  s.directions = p.getInt("directions", s.directions);
  if (s.basis != "sh" && s.basis != "directions") p.fail("basis must be sh or directions");
  if (s.directions < 1 || s.directions > 4096) p.fail("directions must be between 1 and 4096");
  if (s.resolution < 2 || s.resolution > 512) p.fail("resolution must be between 2 and 512");
  if (s.gatherRays < 1) p.fail("gather_rays must be positive");
  if (s.refineRays < 0) p.fail("refine_rays must not be negative");
  if (s.maxGatherRays < s.gatherRays) p.fail("max_gather_rays must be at least gather_rays");
  if (g < 0 || c < 0) p.fail("photon counts must not be negative");
  s.globalPhotons = size_t(g);
  s.causticPhotons = size_t(c);
  return s;
}

IntegratorSettings IntegratorSettings::fromProperties(IntegratorType type, Properties& p) {
  IntegratorSettings s;
  s.type = type;
  s.env = EnvSamplingSettings::fromProperties(p);
  switch (type) {
    case IntegratorType::Path: s.path = PathSettings::fromProperties(p); break;
    case IntegratorType::Direct: s.direct = DirectSettings::fromProperties(p); break;
    case IntegratorType::Photon: s.photon = PhotonSettings::fromProperties(p); break;
    case IntegratorType::Sppm: s.sppm = SppmSettings::fromProperties(p); break;
    case IntegratorType::Grid: s.grid = GridSettings::fromProperties(p); break;
  }
  return s;
}

bool IntegratorSettings::hidesEmitters() const {
  switch (type) {
    case IntegratorType::Path: return path.hideEmitters;
    case IntegratorType::Direct: return direct.hideEmitters;
    case IntegratorType::Photon: return photon.hideEmitters;
    case IntegratorType::Grid: return grid.hideEmitters;
    case IntegratorType::Sppm: return false;
  }
  return false;
}

namespace {

// N of "points-N" or "points-draw-N" where `name` is base + "-" + digits; 0 where it is not.
long long sizeIn(const std::string& name, const std::string& base) {
  const std::string prefix = base + "-";
  if (name.rfind(prefix, 0) != 0) return 0;
  const std::string digits = name.substr(prefix.size());
  if (digits.empty() || digits.size() > 12 || !std::all_of(digits.begin(), digits.end(), [](char c) { return c >= '0' && c <= '9'; }))
    return 0;
  return std::stoll(digits);
}

}  // namespace

void IntegratorSettings::setStrategy(const std::string& name) {
  for (const char* base : {"points-draw", "points"}) {
    const std::string b = base;
    if (name.rfind(b + "-", 0) != 0 || (b == "points" && name.rfind("points-draw", 0) == 0)) continue;
    const long long n = sizeIn(name, b);
    if (n < 1 || n > kMaxCollapsedPoints)
      throw std::runtime_error("strategy '" + name + "': " + b + "-N needs a whole N from 1 to " +
                               std::to_string(kMaxCollapsedPoints));
    setStrategy(b);
    env.pointCount = int(n);
    return;
  }
  findStrategy(name);
  env.strategy = name;
  direct.emitterSamples = direct.bsdfSamples = -1;
}

}  // namespace envgi
