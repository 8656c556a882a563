#include "scene/Scene.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include "envmap/CollapsedMap.h"
#include "materials/BsdfFactory.h"
#include "scene/NameTables.h"

namespace envgi {

namespace {
// Whether material `index`, or any a blend of it may choose, needs the frame along dp/du.
bool needsTangentFrame(const std::vector<Bsdf>& bsdfs, int index, int depth = 0) {
  const Bsdf& b = bsdfs[size_t(index)];
  if (!bsdfIsBlend(b) || depth > kMaxBlendDepth) return bsdfNeedsTangentFrame(b);
  return needsTangentFrame(bsdfs, b.blend0, depth + 1) || needsTangentFrame(bsdfs, b.blend1, depth + 1);
}

// The texels, or a checkerboard's squares, across one unit of (u, v) after to_uv, by axis.
Vec2f texelsPerUnit(const TextureView& t) {
  const float sx = t.type == TextureType::Bitmap ? float(t.width) : 8.f;
  const float sy = t.type == TextureType::Bitmap ? float(t.height) : 8.f;
  return {sx, sy};
}

// Length in texels of the (u, v) step d once to_uv maps it.
float texelLength(const TextureView& t, Vec2f d) {
  const Vec2f s = texelsPerUnit(t);
  const float x = (t.toUv[0] * d.x + t.toUv[1] * d.y) * s.x, y = (t.toUv[3] * d.x + t.toUv[4] * d.y) * s.y;
  return std::sqrt(x * x + y * y);
}

// Cuts each textured light into cells: a triangle into n^2 about half a texel across, a sphere
// into n rows and 2n columns of its (u, v), a texel each where to_uv keeps the texture's grid
// (at most 256 a side, and 2^21 cells in all: past that every light's side count shrinks
// alike). Each cell is weighed by its area times the mean luminance the texture shows at a
// lattice of points over it (a quarter of a texel apart or closer), and the light's radiance
// becomes the mean over it (its power for the choice among lights), at least 1e-3 of the
// texture's mean (lp.radiance until then), so that no light the lattice saw black is never
// chosen. A floor of 1e-3 of the mean weight keeps every cell drawable: a bright spot between
// the lattice's points costs variance, never bias.
void buildLightCells(const std::vector<MeshView>& meshes, const std::vector<TextureView>& textures,
                     std::vector<LightPrim>& lights, std::vector<AliasBin>* cells) {
  cells->clear();
  constexpr float kMaxSide = 256.f;
  constexpr double kMaxCells = double(1 << 21);
  const int meshCount = int(meshes.size());
  // A triangle's (u, v) at its corners, and its longest side in texels.
  auto corners = [&](const LightPrim& lp, Vec2f uv[3]) {
    const MeshView& m = meshes[size_t(lp.geomId)];
    const uint32_t* ix = m.indices + 3 * lp.primId;
    uv[0] = meshUv(m, ix[0], ix[1], ix[2], 0.f, 0.f);
    uv[1] = meshUv(m, ix[0], ix[1], ix[2], 1.f, 0.f);
    uv[2] = meshUv(m, ix[0], ix[1], ix[2], 0.f, 1.f);
  };
  auto longestSide = [&](const LightPrim& lp, const TextureView& t) {
    Vec2f uv[3];
    corners(lp, uv);
    return std::max({texelLength(t, uv[1] - uv[0]), texelLength(t, uv[2] - uv[1]), texelLength(t, uv[0] - uv[2])});
  };
  // A sphere's rows: the texels down its v, or half those across its u, whichever is more.
  auto sphereTexels = [&](const TextureView& t) {
    return std::max(texelLength(t, Vec2f(0.f, 1.f)), 0.5f * texelLength(t, Vec2f(1.f, 0.f)));
  };
  // Each light's extent in texels (a triangle's longest side, a sphere's rows) and side count.
  std::vector<float> texels(lights.size(), 0.f), side(lights.size(), 0.f);
  double total = 0.0;
  for (size_t i = 0; i < lights.size(); ++i) {
    const LightPrim& lp = lights[i];
    if (lp.radianceTexture < 0 || !(lp.area > 0.f)) continue;
    const TextureView& t = textures[size_t(lp.radianceTexture)];
    const bool sphere = lp.geomId >= meshCount;
    texels[i] = sphere ? sphereTexels(t) : longestSide(lp, t);
    side[i] = std::min(std::max(std::ceil(sphere ? texels[i] : 2.f * texels[i]), 1.f), kMaxSide);
    total += (sphere ? 2.0 : 1.0) * double(side[i]) * double(side[i]);
  }
  const float shrink = total > kMaxCells ? float(std::sqrt(kMaxCells / total)) : 1.f;
  std::vector<float> weight;
  std::vector<Color> colour;
  for (size_t i = 0; i < lights.size(); ++i) {
    if (side[i] == 0.f) continue;
    LightPrim& lp = lights[i];
    const TextureView& t = textures[size_t(lp.radianceTexture)];
    const int n = std::max(1, int(side[i] * shrink));
    const bool sphere = lp.geomId >= meshCount;
    const int cellCount = sphere ? sphereCellCount(n) : n * n;
    // Steps a side of a cell's lattice of points: four a texel, within [2, 6]. The lattice
    // takes in the cell's edges and corners, so that a bright texel crossing a sliver of the
    // cell is seen, pulled inside by 1e-3 of the cell, so that a cell whose edges are texel
    // edges does not read its neighbours' texels.
    const float cellTexels = texels[i] / float(n);
    const int k = std::min(6, std::max(2, int(std::ceil(4.f * cellTexels))));
    constexpr float kInset = 1e-3f;
    weight.assign(size_t(cellCount), 0.f);
    colour.assign(size_t(cellCount), Color(0.f));
    // The cell's part of the light's area.
    auto share = [&](int c) { return sphere ? sphereCellShare(c, n) : 1.f / float(cellCount); };
    // The cells apart (a 512 x 256 texture's two triangles read 3.8 M points), summed after in
    // order, so that the tables do not depend on the thread count.
    tbb::parallel_for(tbb::blocked_range<int>(0, cellCount, 256), [&](const tbb::blocked_range<int>& range) {
      for (int c = range.begin(); c < range.end(); ++c) {
        float cellSum = 0.f;
        Color cellColour(0.f);
        int points = 0;
        auto at = [&](Vec2f uv) {
          const Color L = textureEval(t, uv);
          cellSum += luminance(L);
          cellColour += L;
          ++points;
        };
        if (sphere) {
          const int iv = c / (2 * n), iu = c - iv * 2 * n;
          for (int a = 0; a <= k; ++a)
            for (int b = 0; b <= k; ++b) {
              const float fa = kInset + (1.f - 2.f * kInset) * float(a) / float(k);
              const float fb = kInset + (1.f - 2.f * kInset) * float(b) / float(k);
              at(Vec2f((float(iu) + fa) / float(2 * n), (float(iv) + fb) / float(n)));
            }
        } else {
          const MeshView& m = meshes[size_t(lp.geomId)];
          const uint32_t* ix = m.indices + 3 * lp.primId;
          const Vec2f v0 = triangleCellCorner(c, n, 0), v1 = triangleCellCorner(c, n, 1), v2 = triangleCellCorner(c, n, 2);
          const Vec2f centre = (v0 + v1 + v2) * (1.f / 3.f);
          auto atBary = [&](Vec2f b) {
            b = b + (centre - b) * kInset;
            at(meshUv(m, ix[0], ix[1], ix[2], b.x, b.y));
          };
          for (int a = 0; a <= k; ++a)
            for (int b = 0; a + b <= k; ++b) {
              const float fa = float(a) / float(k), fb = float(b) / float(k);
              atBary(v0 * (1.f - fa - fb) + v1 * fa + v2 * fb);
            }
          atBary(centre);
        }
        weight[size_t(c)] = share(c) * cellSum / float(points);
        colour[size_t(c)] = cellColour * (share(c) / float(points));
      }
    });
    Color sum(0.f);
    double totalShare = 0.0;
    for (int c = 0; c < cellCount; ++c) sum += colour[size_t(c)], totalShare += double(share(c));
    double mean = 0.0;
    for (float w : weight) mean += double(w);
    mean /= double(weight.size());
    for (float& w : weight) w = std::max(w, float(1e-3 * mean));
    const Color own = sum / float(totalShare), least = lp.radiance * 1e-3f;
    lp.radiance = luminance(own) >= luminance(least) ? own : least;
    if (cellCount == 1) continue;  // one cell: uniform, as without
    AliasTable table(weight.data(), weight.size());
    const AliasTableView v = table.view();
    lp.cellOffset = int(cells->size());
    lp.cells = n;
    cells->insert(cells->end(), v.bins, v.bins + v.n);
  }
}
}  // namespace

void Scene::requireCompensationCovered() const {
  // MIS compensation (Karlik et al. 2019) samples max(L - mean, 0): the map's dim directions get
  // density 0, which only BSDF samples MIS-weighted beside them cover. An estimator without such
  // samples would lose that light silently.
  if (!env || !env->options().misCompensation) return;
  const EnvStrategy s = findStrategy(integrator.env.strategy).env;
  // Uniform and cosine read none of the map's tables; the adaptive quadtree balances plain power.
  if (s == EnvStrategy::Uniform || s == EnvStrategy::Cosine || s == EnvStrategy::Adaptive) return;
  const StrategyName& sn = findStrategy(integrator.env.strategy);
  const int emitterSamples = integrator.direct.emitterSamples >= 0 ? integrator.direct.emitterSamples : sn.emitterSamples;
  const int bsdfSamples = integrator.direct.bsdfSamples >= 0 ? integrator.direct.bsdfSamples : sn.bsdfSamples;
  std::string why;
  if (isCollapsedMap(s))
    why = "the collapsed map's lights are drawn from its density and no BSDF sample finds them";
  else if (integrator.type == IntegratorType::Photon || integrator.type == IntegratorType::Grid)
    why = std::string("the ") + integratorName(integrator.type) +
          " integrator's gathers take light samples of the map without BSDF samples";
  else if (integrator.type == IntegratorType::Direct && emitterSamples > 0 && bsdfSamples == 0)
    why = "the direct integrator takes light samples with bsdf_samples 0";
  if (!why.empty())
    throw std::runtime_error("mis_compensation: " + why +
                             ", so the map's dim directions would be lost; turn mis_compensation off, or use path or "
                             "direct with BSDF samples (bsdf_samples > 0, or the strategy 'mis')");
}

void Scene::finalize() {
  if (bsdfs.empty()) bsdfs.push_back(Bsdf{});
  // A rough plastic whose alpha or ior changed since loading reads the tables of its new ones.
  for (Bsdf& b : bsdfs) attachRoughCoat(b);
  // The collapsed map, for the points strategies: made here so every device reads the same lights.
  if (env && isCollapsedMap(findStrategy(integrator.env.strategy).env)) {
    if (integrator.env.pointMethod == "mediancut") env->setPoints(collapseByMedianCut(*env, integrator.env.pointCount));
    else if (integrator.env.pointMethod == "sample")
      env->setPoints(collapseByWeightedSampling(*env, integrator.env.pointCount, sampler.seed));
    else throw std::runtime_error("unknown point_method '" + integrator.env.pointMethod + "' (sample, mediancut)");
  }
  requireCompensationCovered();
  // Embree reads vertices with 16-byte loads: keep one element of slack after the last one.
  for (TriangleMesh& m : meshes) m.positions.reserve(m.positions.size() + 1);
  for (TriangleMesh& m : prototypes) m.positions.reserve(m.positions.size() + 1);
  meshViews_.assign(meshGeometryCount(), MeshView{});
  sphereViews_.assign(spheres.size(), SphereView{});
  lights_.clear();
  Vec3f lo(INFINITY), hi(-INFINITY);
  for (const ShapeEntry& s : shapes) {
    if (s.isSphere) {
      const Sphere& sp = spheres[s.index];
      SphereView& v = sphereViews_[s.index];
      v.center = sp.center;
      v.radius = sp.radius;
      v.axes = sp.axes;
      v.bsdf = s.bsdf;
      v.flipNormals = sp.flipNormals;
      lo = vmin(lo, sp.center - Vec3f(sp.radius));
      hi = vmax(hi, sp.center + Vec3f(sp.radius));
      if (s.emissive) {
        v.light = int(lights_.size());
        lights_.push_back(
            {int(geometryId(s)), 0, s.radiance, 4.f * kPi * sp.radius * sp.radius, s.radianceTexture});
      }
    } else {
      const size_t id = geometryId(s);
      const TriangleMesh& m = meshOfGeometry(id);
      MeshView& v = meshViews_[id];
      v.positions = m.positions.data();
      v.normals = m.normals.empty() ? nullptr : m.normals.data();
      v.uvs = m.uvs.empty() ? nullptr : m.uvs.data();
      v.indices = m.indices.data();
      v.triangleCount = int(m.triangleCount());
      v.vertexCount = int(m.positions.size());
      v.bsdf = s.bsdf;
      v.anisotropic = s.bsdf >= 0 && size_t(s.bsdf) < bsdfs.size() && needsTangentFrame(bsdfs, s.bsdf);
      if (s.isInstance) {
        if (s.emissive) throw std::runtime_error("internal: an instanced mesh cannot be an area light");
        const MeshInstance& inst = instances[s.index];
        v.toWorld = &inst.toWorld;
        for (const Vec3f& p : m.positions) {
          Vec3f w = inst.toWorld.point(p);
          lo = vmin(lo, w);
          hi = vmax(hi, w);
        }
        continue;
      }
      for (const Vec3f& p : m.positions) {
        lo = vmin(lo, p);
        hi = vmax(hi, p);
      }
      if (s.emissive) {
        v.lightOffset = int(lights_.size());
        for (size_t t = 0; t < m.triangleCount(); ++t) {
          Vec3f p0 = m.positions[m.indices[3 * t]], p1 = m.positions[m.indices[3 * t + 1]],
                p2 = m.positions[m.indices[3 * t + 2]];
          lights_.push_back(
              {int(s.index), int(t), s.radiance, 0.5f * length(cross(p1 - p0, p2 - p0)), s.radianceTexture});
        }
      }
    }
  }
  for (const MeshView& v : meshViews_)
    if (!v.positions) throw std::runtime_error("internal: mesh without a shape entry");
  if (!(lo.x <= hi.x)) lo = hi = Vec3f(0.f);
  textureViews_.clear();
  for (const Texture& t : textures) {
    textureViews_.push_back(t.params);
    textureViews_.back().texels = t.texels.empty() ? nullptr : t.texels.data();
  }
  buildLightCells(meshViews_, textureViews_, lights_, &lightCells_);
  std::vector<float> power(lights_.size());
  for (size_t i = 0; i < lights_.size(); ++i) power[i] = luminance(lights_[i].radiance) * lights_[i].area;
  if (!lights_.empty()) lightTable_ = AliasTable(power.data(), power.size());

  view_ = SceneView{};
  view_.meshes = meshViews_.data();
  view_.meshCount = int(meshViews_.size());
  view_.spheres = sphereViews_.data();
  view_.sphereCount = int(sphereViews_.size());
  view_.bsdfs = bsdfs.data();
  view_.textures = textureViews_.data();
  view_.lights = lights_.data();
  view_.lightCount = int(lights_.size());
  if (!lights_.empty()) view_.lightSelect = lightTable_.view();
  view_.lightCells = lightCells_.empty() ? nullptr : lightCells_.data();
  view_.lightCellCount = int(lightCells_.size());
  view_.deltaLights = deltaLights.empty() ? nullptr : deltaLights.data();
  view_.deltaLightCount = int(deltaLights.size());
  view_.hasEnvironment = env != nullptr;
  for (const Bsdf& b : bsdfs) view_.hasMasks = view_.hasMasks || bsdfIsMasked(b);
  if (env) view_.env = env->view();
  view_.camera = camera;
  view_.boundsMin = lo;
  view_.boundsMax = hi;
}

size_t Scene::triangleCount() const {
  size_t n = 0;
  for (const TriangleMesh& m : meshes) n += m.triangleCount();
  for (const MeshInstance& i : instances) n += prototypes[size_t(i.prototype)].triangleCount();
  return n;
}

size_t Scene::geometryBytes() const {
  size_t b = 0;
  for (const TriangleMesh& m : meshes) b += m.bytes();
  for (const TriangleMesh& m : prototypes) b += m.bytes();
  return b + instances.size() * sizeof(MeshInstance) + spheres.size() * sizeof(Sphere);
}

}  // namespace envgi
