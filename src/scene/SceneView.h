// The scene as plain data that kernels read: meshes, spheres, materials, lights, camera.
#pragma once

#include <cstring>
#include <new>

#include "core/Atan2.h"
#include "core/Frame.h"
#include "envmap/EnvironmentMapView.h"
#include "materials/Bsdf.h"
#include "materials/Texture.h"
#include "sampling/AliasTable.h"
#include "sampling/Pcg32.h"
#include "sampling/SphereCells.h"
#include "sampling/TriangleCells.h"
#include "scene/Camera.h"
#include "scene/DeltaLight.h"
#include "scene/Ray.h"

namespace envgi {

struct MeshView {
  const Vec3f* positions = nullptr;  // world space, or toWorld's object space
  const Vec3f* normals = nullptr;    // as positions, may be null (face normals)
  const Vec2f* uvs = nullptr;        // may be null
  const uint32_t* indices = nullptr; // 3 a triangle
  int triangleCount = 0;
  int bsdf = 0;
  int lightOffset = -1;  // index of triangle 0 in the light list, -1 when not emissive
  bool anisotropic = false;  // its material needs a frame along dp/du (bsdfNeedsTangentFrame)
  int vertexCount = 0;
  // An instance's placement of a shared mesh (Scene::instances); null for a mesh of its own.
  // Only light-free meshes are placed so: lights read positions as world space.
  const Transform* toWorld = nullptr;
};

struct SphereView {
  Vec3f center;
  float radius = 1.f;
  int bsdf = 0;
  int light = -1;
  bool flipNormals = false;
  Frame axes{{1.f, 0.f, 0.f}, {0.f, 1.f, 0.f}, {0.f, 0.f, 1.f}};  // to_world's axes, for (u, v)
};

// One emitting primitive: a triangle of a mesh or a whole sphere.
struct LightPrim {
  int geomId;    // scene geometry numbering (meshes, then spheres)
  int primId;
  Color radiance;  // with a texture, its mean over the primitive: its power for the choice among lights
  float area;
  int radianceTexture;  // -1: radiance everywhere; else read at the (u, v) the light leaves from
  // A textured primitive's points are drawn by the texture: a cell from the alias table at
  // SceneView::lightCells + cellOffset, then a point uniformly (by area) in it; a triangle has
  // cells^2 cells (TriangleCells.h), a sphere 2 cells^2 (SphereCells.h). cells 0: uniformly
  // over the primitive (untextured lights).
  int cellOffset = 0;
  int cells = 0;
};

struct SurfaceInteraction {
  Vec3f p;
  Vec3f ng;  // geometric normal (flip_normals applied: meshes by winding, spheres by flag)
  Frame shading;
  Vec2f uv;
  // dp/du and dp/dv along the shading frame's s and t, filled in only for a bump-mapped
  // material (the only reader).
  Vec2f dpdu{0.f, 0.f}, dpdv{0.f, 0.f};
  int bsdf = 0;
  // A blend's other material, which the path tracer evaluates beside `bsdf` (SceneView::
  // blendPartner), and its weight in the mix; -1: none.
  int partner = -1;
  float partnerWeight = 0.f;
  int light = -1;
  float t = 0.f;
};

// A vector's components along a frame's s and t.
ENVGI_INLINE Vec2f tangentPart(const Frame& f, Vec3f v) { return Vec2f(dot(v, f.s), dot(v, f.t)); }

// Mitsuba's bumpmap normal in the shading frame (local): dp/du and dp/dv keep their tangential
// parts and take the height's gradient g as their normal parts; the normal is their cross
// product, on the unmapped normal's side. A surface without (u, v) derivatives stays as it is.
ENVGI_INLINE Vec3f bumpedNormal(Vec2f g, Vec2f dpdu, Vec2f dpdv) {
  Vec3f n = cross(Vec3f(dpdu.x, dpdu.y, g.x), Vec3f(dpdv.x, dpdv.y, g.y));
  float l2 = lengthSq(n);
  if (!(l2 > 0.f && l2 < INFINITY)) return Vec3f(0.f, 0.f, 1.f);
  n = n * (1.f / std::sqrt(l2));
  return n.z < 0.f ? -n : n;
}

// A triangle's (u, v) at barycentrics (b1, b2) of its vertices i1 and i2: the mesh's own where
// it has them, the barycentrics themselves where it has none.
ENVGI_INLINE Vec2f meshUv(const MeshView& m, uint32_t i0, uint32_t i1, uint32_t i2, float b1, float b2) {
  return m.uvs ? m.uvs[i0] * (1.f - b1 - b2) + m.uvs[i1] * b1 + m.uvs[i2] * b2 : Vec2f(b1, b2);
}
// Mitsuba's sphere coordinates at the unit radial direction n: u the azimuth about local z from
// local x, v the polar angle (two inverse trigonometric functions, so only where a texture reads them).
ENVGI_INLINE Vec2f sphereUv(const SphereView& s, Vec3f n) {
  Vec3f l = s.axes.toLocal(n);
  float phi = polyAtan2(l.y, l.x);
  return Vec2f((phi < 0.f ? phi + 2.f * kPi : phi) * (0.5f * kInvPi), acosf(fminf(fmaxf(l.z, -1.f), 1.f)) * kInvPi);
}

// A number in [0, 1) from a ray and a surface crossing it (a geometry's id and the triangle, or
// which of a sphere's two crossings): the same on either tracer and device, and apart for each
// crossing along one ray.
ENVGI_INLINE float rayCrossingHash(const Ray& r, int geomId, uint32_t crossing) {
  uint32_t w[6];
  std::memcpy(&w[0], &r.o, sizeof(Vec3f));
  std::memcpy(&w[3], &r.d, sizeof(Vec3f));
  uint64_t x = mixBits((uint64_t(w[0]) << 32) | w[1]);
  x = hashCombine(x, (uint64_t(w[2]) << 32) | w[3]);
  x = hashCombine(x, (uint64_t(w[4]) << 32) | w[5]);
  x = hashCombine(x, (uint64_t(uint32_t(geomId)) << 32) | crossing);
  return float(x >> 40) * (1.f / 16777216.f);
}

// Room for a textured material's copy at a hit, left unwritten where the material has no
// texture (a Bsdf would store its defaults there at every hit).
struct BsdfScratch {
  alignas(Bsdf) unsigned char bytes[sizeof(Bsdf)];
};

struct SceneView {
  const MeshView* meshes = nullptr;
  int meshCount = 0;
  const SphereView* spheres = nullptr;
  int sphereCount = 0;
  const Bsdf* bsdfs = nullptr;
  const TextureView* textures = nullptr;
  const LightPrim* lights = nullptr;
  int lightCount = 0;
  AliasTableView lightSelect;  // area lights by power
  const AliasBin* lightCells = nullptr;  // the textured triangles' cell tables, one after another
  int lightCellCount = 0;
  const DeltaLight* deltaLights = nullptr;
  int deltaLightCount = 0;
  bool hasEnvironment = false;
  bool hasMasks = false;  // some material has a mask (Bsdf::opacity): the tracers ask stopsAtMask
  EnvironmentMapView env;
  Camera camera;
  Vec3f boundsMin, boundsMax;

  // Next-event estimation picks the map, the area lights as one (then one of them by power), or
  // one delta light, each of these alike, as Cycles 3.4 gives each lamp and the background a
  // share: these are their chances (deltaSelectProb the delta lights' together).
  ENVGI_HD float lightKinds() const { return float(int(hasEnvironment) + int(lightCount > 0) + deltaLightCount); }
  ENVGI_HD float envSelectProb() const { return hasEnvironment ? 1.f / lightKinds() : 0.f; }
  ENVGI_HD float areaSelectProb() const { return lightCount > 0 ? 1.f / lightKinds() : 0.f; }
  ENVGI_HD float deltaSelectProb() const { return deltaLightCount > 0 ? float(deltaLightCount) / lightKinds() : 0.f; }

  ENVGI_HD SurfaceInteraction interaction(const Ray& ray, const Hit& h) const {
    SurfaceInteraction si;
    si.t = h.t;
    if (h.geomId < meshCount) {
      const MeshView& m = meshes[h.geomId];
      uint32_t i0 = m.indices[3 * h.primId], i1 = m.indices[3 * h.primId + 1], i2 = m.indices[3 * h.primId + 2];
      Vec3f p0 = m.positions[i0], p1 = m.positions[i1], p2 = m.positions[i2];
      // An instance's triangle is placed first, so that everything below (the geometric
      // normal's side under a mirroring transform included) is what a copy of it would give.
      if (m.toWorld) p0 = m.toWorld->point(p0), p1 = m.toWorld->point(p1), p2 = m.toWorld->point(p2);
      float b1 = h.u, b2 = h.v, b0 = 1.f - b1 - b2;
      si.p = p0 * b0 + p1 * b1 + p2 * b2;
      Vec3f ng = normalize(cross(p1 - p0, p2 - p0));
      Vec3f ns = ng;
      if (m.normals) {
        Vec3f n = m.normals[i0] * b0 + m.normals[i1] * b1 + m.normals[i2] * b2;
        if (m.toWorld) n = m.toWorld->normal(n);
        if (lengthSq(n) > 0.f) ns = normalize(n);
        if (dot(ns, ng) < 0.f) ng = -ng;  // geometric normal agrees with the mesh's own normals
      }
      si.ng = ng;
      si.uv = meshUv(m, i0, i1, i2, b1, b2);
      const int bsdf = blendChoice(m.bsdf, si.uv, ray, h.geomId, uint32_t(h.primId));
      si.shading = Frame::fromNormal(ns);
      if (m.anisotropic) {
        // dp/du from the triangle's (u, v), the barycentric ones where the mesh has none.
        Vec2f t0 = m.uvs ? m.uvs[i0] : Vec2f(0.f, 0.f), t1 = m.uvs ? m.uvs[i1] : Vec2f(1.f, 0.f),
              t2 = m.uvs ? m.uvs[i2] : Vec2f(0.f, 1.f);
        Vec2f d1 = t1 - t0, d2 = t2 - t0;
        float det = d1.x * d2.y - d1.y * d2.x;
        if (det != 0.f) {
          Vec3f dpdu = ((p1 - p0) * d2.y - (p2 - p0) * d1.y) / det;
          si.shading = Frame::fromNormalAndTangent(ns, dpdu);
          if (bsdfs[bsdf].bumpTexture >= 0) {
            Vec3f dpdv = ((p2 - p0) * d1.x - (p1 - p0) * d2.x) / det;
            si.dpdu = tangentPart(si.shading, dpdu);
            si.dpdv = tangentPart(si.shading, dpdv);
          }
        }
      }
      si.bsdf = bsdf;
      if (bsdf != m.bsdf) blendPartner(m.bsdf, &si);
      si.light = m.lightOffset >= 0 ? m.lightOffset + h.primId : -1;
    } else {
      const SphereView& s = spheres[h.geomId - meshCount];
      Vec3f p = ray.o + ray.d * h.t;
      Vec3f n = normalize(p - s.center);
      si.p = s.center + n * s.radius;  // re-projected: removes the hit point's float error
      int bsdf = s.bsdf;
      const bool blend = bsdfIsBlend(bsdfs[bsdf]);
      const bool texturedLight = s.light >= 0 && lights[s.light].radianceTexture >= 0;
      // A blend reads its weight at uv (blendChoice, and blendPartner below), before the normal's flip.
      si.uv = blend || bsdfHasTexture(bsdfs[bsdf]) || texturedLight ? sphereUv(s, n) : Vec2f(0.f, 0.f);
      if (blend) bsdf = blendChoice(bsdf, si.uv, ray, h.geomId, dot(n, ray.d) > 0.f ? 1u : 0u);
      Vec3f radial = n;
      if (s.flipNormals) n = -n;
      si.ng = n;
      si.shading = Frame::fromNormal(n);
      if (bsdfNeedsTangentFrame(bsdfs[bsdf])) {
        // dp/du runs along the azimuth about the sphere's own z, as Mitsuba's.
        Vec3f l = s.axes.toLocal(radial);
        Vec3f dpdu = s.axes.toWorld(Vec3f(-l.y, l.x, 0.f)) * (2.f * kPi * s.radius);
        si.shading = Frame::fromNormalAndTangent(n, dpdu);
        if (bsdfs[bsdf].bumpTexture >= 0) {
          // Mitsuba's sphere: v = theta / pi, so dp/dv = pi r (cos phi cos theta, sin phi cos theta, -sin theta).
          float sinTheta = std::sqrt(fmaxf(0.f, l.x * l.x + l.y * l.y));
          Vec3f dpdv = sinTheta > 0.f ? s.axes.toWorld(Vec3f(l.x * l.z / sinTheta, l.y * l.z / sinTheta, -sinTheta)) * (kPi * s.radius)
                                      : Vec3f(0.f, 0.f, 0.f);
          si.dpdu = tangentPart(si.shading, dpdu);
          si.dpdv = tangentPart(si.shading, dpdv);
        }
      }
      si.bsdf = bsdf;
      if (blend) blendPartner(s.bsdf, &si);
      si.light = s.light;
    }
    return si;
  }

  // The material a ray finds where it crosses a surface of material `index` (a crossing as
  // rayCrossingHash's): `index` itself, or for a blend one of its two, chosen with the chance of
  // its weight at uv by a hash of the crossing (apart from the mask's, which decides whether the
  // ray stopped there, and apart for each level of blends nested in blends).
  ENVGI_HD int blendChoice(int index, Vec2f uv, const Ray& ray, int geomId, uint32_t crossing) const {
    return bsdfIsBlend(bsdfs[index]) ? blendChoiceOf(index, uv, ray, geomId, crossing) : index;
  }
  // blendChoice's walk down nested blends, out of line on the GPU (docs/gpu.md).
  ENVGI_HD_NOINLINE int blendChoiceOf(int index, Vec2f uv, const Ray& ray, int geomId, uint32_t crossing) const {
    for (int level = 0; level < kMaxBlendDepth && bsdfIsBlend(bsdfs[index]); ++level) {
      const Bsdf& b = bsdfs[index];
      // A weight of 1 or more always picks blend1, of 0 or less (or NaN) blend0, as Mitsuba clamps it.
      index = rayCrossingHash(ray, geomId ^ ((level + 1) << 24), crossing) < blendWeightAt(b, uv) ? b.blend1 : b.blend0;
    }
    return index;
  }
  // Blend b's weight at uv (its texture's luminance, or its number), before any clamping.
  ENVGI_HD float blendWeightAt(const Bsdf& b, Vec2f uv) const {
    return b.blendWeightTexture >= 0 ? luminance(textureEval(textures[b.blendWeightTexture], uv)) : b.blendWeight;
  }

  // Where blend `index` (one level, of two plain materials) chose si->bsdf, the other one and
  // its weight, so that the path tracer evaluates the mix (1 - w) f0 + w f1 as Mitsuba and
  // Cycles do, not only the one chosen: its next-event estimate then carries both, and its BSDF
  // sample is weighted by the mix's density (one-sample MIS over the two). Left out (the choice
  // alone, as pbrt-v4's MixMaterial) for nested blends and for materials that transmit or need
  // their own shading frame, which the two would not share.
  ENVGI_HD_NOINLINE void blendPartner(int index, SurfaceInteraction* si) const {
    const Bsdf& b = bsdfs[index];
    if (si->bsdf != b.blend0 && si->bsdf != b.blend1) return;
    const int other = si->bsdf == b.blend0 ? b.blend1 : b.blend0;
    for (int i : {b.blend0, b.blend1}) {
      const Bsdf& c = bsdfs[i];
      if (bsdfIsBlend(c) || bsdfTransmits(c) || bsdfNeedsTangentFrame(c) || bsdfIsMasked(c)) return;
    }
    const float w = fminf(fmaxf(blendWeightAt(b, si->uv), 0.f), 1.f);  // as blendChoiceOf: NaN picks blend0 alone
    const float share = other == b.blend1 ? w : 1.f - w;
    if (!(share > 0.f)) return;
    si->partner = other;
    si->partnerWeight = share;
  }

  // The material at a hit, without the rest of interaction() (a blend's own entry).
  ENVGI_HD int bsdfIndexAt(const Hit& h) const {
    return h.geomId < meshCount ? meshes[h.geomId].bsdf : spheres[h.geomId - meshCount].bsdf;
  }

  // Whether a ray stops at hit h: always at an opaque surface, at a masked one with the chance
  // of its opacity there (Mitsuba's mask), drawn from rayCrossingHash, as pbrt-v4's stochastic alpha
  // test does, so that the tracers can decide it while they traverse and no sampler dimension
  // depends on what a ray passed through.
  ENVGI_HD bool stopsAtMask(const Ray& ray, const Hit& h) const {
    const Bsdf& b = bsdfs[bsdfIndexAt(h)];
    if (!bsdfIsMasked(b)) return true;
    float a = b.opacity;
    uint32_t crossing = uint32_t(h.primId);
    if (h.geomId < meshCount) {
      if (b.opacityTexture >= 0) {
        const MeshView& m = meshes[h.geomId];
        const uint32_t* ix = m.indices + 3 * size_t(h.primId);
        a = luminance(textureEval(textures[b.opacityTexture], meshUv(m, ix[0], ix[1], ix[2], h.u, h.v)));
      }
    } else {
      // A ray may cross a sphere twice: on the way in and on the way out, each decided apart.
      const SphereView& s = spheres[h.geomId - meshCount];
      Vec3f radial = ray.o + ray.d * h.t - s.center;
      crossing = dot(radial, ray.d) > 0.f ? 1u : 0u;
      if (b.opacityTexture >= 0) a = luminance(textureEval(textures[b.opacityTexture], sphereUv(s, normalize(radial))));
    }
    // An opacity of 1 or more always stops the ray, of 0 or less (or NaN) never, as Mitsuba clamps it.
    return rayCrossingHash(ray, h.geomId, crossing) < a;
  }

  // Material `index` at surface coordinates uv: its textured colours looked up there, as a
  // copy. Kernels use the scratch form below, which copies only a textured material.
  ENVGI_HD Bsdf bsdfAt(int index, Vec2f uv) const {
    Bsdf b = bsdfs[index];
    if (b.reflectanceTexture >= 0) b.reflectance = textureEval(textures[b.reflectanceTexture], uv);
    if (b.specularReflectanceTexture >= 0)
      b.specularReflectance = textureEval(textures[b.specularReflectanceTexture], uv);
    if (b.specularTransmittanceTexture >= 0)
      b.specularTransmittance = textureEval(textures[b.specularTransmittanceTexture], uv);
    // A roughness texture reads as its luminance, within the scene format's bounds (NaN: the lower).
    auto roughness = [&](int t) { return fminf(fmaxf(luminance(textureEval(textures[t], uv)), kMinAlpha), kMaxAlpha); };
    if (b.alphaTexture >= 0) b.alpha = roughness(b.alphaTexture);
    if (b.alphaVTexture >= 0) b.alphaV = roughness(b.alphaVTexture);
    if (b.normalMapTexture >= 0) b.mappedNormal = mappedNormalAt(textures[b.normalMapTexture], uv);
    // The principled BSDF's roughness and metallic: luminance within [0, 1] (NaN: 0).
    auto unit = [&](int t) { return fminf(fmaxf(luminance(textureEval(textures[t], uv)), 0.f), 1.f); };
    if (b.roughnessTexture >= 0) b.principled.roughness = unit(b.roughnessTexture);
    if (b.metallicTexture >= 0) b.principled.metallic = unit(b.metallicTexture);
    return b;
  }
  // A normal map's texel as a unit normal: rgb = (n + 1) / 2, relative to the shading frame; one
  // that decodes to no direction at all leaves the frame as it is.
  ENVGI_HD static Vec3f mappedNormalAt(const TextureView& t, Vec2f uv) {
    Color c = textureEval(t, uv);
    Vec3f n(2.f * c.x - 1.f, 2.f * c.y - 1.f, 2.f * c.z - 1.f);
    float l2 = lengthSq(n);
    return l2 > 0.f && l2 < INFINITY ? n * (1.f / std::sqrt(l2)) : Vec3f(0.f, 0.f, 1.f);
  }
  // The same, without a copy where the material has no texture: the scene's own entry, read a
  // field at a time where used. A copy kept whole through a bounce held ~60 more registers a
  // GPU thread (156 against 96 on sm_90): 3 blocks an SM instead of 5. `scratch` holds a
  // textured copy.
  // The surface's derivatives (SurfaceInteraction's dpdu, dpdv) are what a bump map reads;
  // without them (zero) it leaves the frame as it is.
  ENVGI_HD const Bsdf& bsdfAt(int index, Vec2f uv, Vec2f dpdu, Vec2f dpdv, BsdfScratch* scratch) const {
    const Bsdf& b = bsdfs[index];
    if (!bsdfHasTexture(b)) return b;
    return texturedCopy(index, uv, dpdu, dpdv, scratch);
  }
  // bsdfAt's copy of a textured material. Out of line on the GPU, as the rarer branches of the
  // path kernel are, to keep its hot code small (docs/gpu.md).
  ENVGI_HD_NOINLINE const Bsdf& texturedCopy(int index, Vec2f uv, Vec2f dpdu, Vec2f dpdv, BsdfScratch* scratch) const {
    Bsdf* copy = new (scratch->bytes) Bsdf(bsdfAt(index, uv));
    if (copy->bumpTexture >= 0)
      copy->mappedNormal = bumpedNormal(textureLuminanceGradient(textures[copy->bumpTexture], uv) * copy->bumpScale, dpdu, dpdv);
    return *copy;
  }
  ENVGI_HD const Bsdf& bsdfAt(int index, Vec2f uv, BsdfScratch* scratch) const {
    return bsdfAt(index, uv, Vec2f(0.f, 0.f), Vec2f(0.f, 0.f), scratch);
  }
  ENVGI_HD const Bsdf& bsdfAt(const SurfaceInteraction& si, BsdfScratch* scratch) const {
    return bsdfAt(si.bsdf, si.uv, si.dpdu, si.dpdv, scratch);
  }
  // The blend partner's material at si (blendPartner), or none.
  ENVGI_HD const Bsdf* partnerAt(const SurfaceInteraction& si, BsdfScratch* scratch) const {
    return si.partner >= 0 ? &bsdfAt(si.partner, si.uv, si.dpdu, si.dpdv, scratch) : nullptr;
  }

  // What interaction() reads for a triangle hit, asked for ahead (CPU only: a batch of hits
  // prefetches its triangles' indices, then their vertices, so that the misses overlap).
  void prefetchTriangle(const Hit& h) const {
    if (h.geomId < meshCount) prefetchLine(meshes[h.geomId].indices + 3 * size_t(h.primId));
  }
  void prefetchVertices(const Hit& h) const {
    if (h.geomId >= meshCount) return;
    const MeshView& m = meshes[h.geomId];
    const uint32_t* ix = m.indices + 3 * size_t(h.primId);
    for (int c = 0; c < 3; ++c) {
      prefetchLine(m.positions + ix[c]);
      if (m.normals) prefetchLine(m.normals + ix[c]);
    }
  }

  // The radiance a light primitive emits at (u, v): its texture there, if it has one.
  ENVGI_HD Color lightRadiance(const LightPrim& lp, Vec2f uv) const {
    return lp.radianceTexture >= 0 ? textureEval(textures[lp.radianceTexture], uv) : lp.radiance;
  }
  // The density over a light primitive's area of the point sampleLightPrim draws, at q on it.
  ENVGI_HD float lightAreaPdf(const LightPrim& lp, Vec3f q) const {
    if (lp.cells == 0) return 1.f / lp.area;
    if (lp.geomId >= meshCount) {
      const SphereView& s = spheres[lp.geomId - meshCount];
      const int cell = sphereCellOf(sphereUv(s, normalize(q - s.center)), lp.cells);
      return lightCells[lp.cellOffset + cell].pmf / (sphereCellShare(cell, lp.cells) * lp.area);
    }
    const MeshView& m = meshes[lp.geomId];
    const uint32_t* ix = m.indices + 3 * lp.primId;
    const Vec2f b = triangleBarycentrics(q, m.positions[ix[0]], m.positions[ix[1]], m.positions[ix[2]]);
    const int n = lp.cells, cell = triangleCellOf(b, n);
    return lightCells[lp.cellOffset + cell].pmf * float(n * n) / lp.area;
  }
  // Emitted radiance leaving a light primitive towards w (one-sided, like Mitsuba's area).
  ENVGI_HD Color emitted(const SurfaceInteraction& si, Vec3f w) const {
    if (si.light < 0 || dot(si.ng, w) <= 0.f) return Color(0.f);
    return lightRadiance(lights[si.light], si.uv);
  }
};

// A textured light's cell, drawn from its table by u, and through *inside the point's place in
// it from the bits the choice left over.
ENVGI_INLINE int drawLightCell(const SceneView& sc, const LightPrim& lp, int cellCount, Vec2f u, float* pmf,
                               Vec2f* inside) {
  float rest;
  const int cell = AliasTableView{sc.lightCells + lp.cellOffset, cellCount}.sample(u, pmf, &rest);
  *inside = splitLeftover(rest);
  return cell;
}

// A point on a light primitive: its position, normal, the radiance it emits there and its
// density over the primitive's area (1 / area unless the primitive is drawn by its texture).
ENVGI_INLINE void sampleLightPrim(const SceneView& sc, const LightPrim& lp, Vec2f u, Vec3f* p, Vec3f* n, Color* Le,
                                  float* areaPdf) {
  *Le = lp.radiance;
  *areaPdf = 1.f / lp.area;
  if (lp.geomId < sc.meshCount) {
    const MeshView& m = sc.meshes[lp.geomId];
    uint32_t i0 = m.indices[3 * lp.primId], i1 = m.indices[3 * lp.primId + 1], i2 = m.indices[3 * lp.primId + 2];
    Vec3f p0 = m.positions[i0], p1 = m.positions[i1], p2 = m.positions[i2];
    Vec2f b;
    if (lp.cells > 0) {
      const int cellCount = lp.cells * lp.cells;
      float pmf;
      Vec2f inside;
      const int cell = drawLightCell(sc, lp, cellCount, u, &pmf, &inside);
      b = sampleTriangleCell(cell, lp.cells, inside);
      *areaPdf = pmf * float(cellCount) / lp.area;
    } else {
      b = sampleUniformTriangle(u);
    }
    *p = p0 * (1.f - b.x - b.y) + p1 * b.x + p2 * b.y;
    if (lp.radianceTexture >= 0) *Le = sc.lightRadiance(lp, meshUv(m, i0, i1, i2, b.x, b.y));
    Vec3f ng = normalize(cross(p1 - p0, p2 - p0));
    if (m.normals) {
      Vec3f ns = m.normals[i0] + m.normals[i1] + m.normals[i2];
      if (dot(ns, ng) < 0.f) ng = -ng;
    }
    *n = ng;
  } else {
    const SphereView& s = sc.spheres[lp.geomId - sc.meshCount];
    Vec3f d;
    if (lp.cells > 0) {
      float pmf;
      Vec2f inside;
      const int cell = drawLightCell(sc, lp, sphereCellCount(lp.cells), u, &pmf, &inside);
      d = s.axes.toWorld(sampleSphereCell(cell, lp.cells, inside));
      *areaPdf = pmf / (sphereCellShare(cell, lp.cells) * lp.area);
    } else {
      d = sampleUniformSphere(u);
    }
    *p = s.center + d * s.radius;
    *n = s.flipNormals ? -d : d;
    if (lp.radianceTexture >= 0) *Le = sc.lightRadiance(lp, sphereUv(s, d));
  }
}

// Picks an area-light primitive by power (u2) and a point on it (u), with the radiance it emits
// there and the point's density over the primitive's area.
ENVGI_INLINE const LightPrim& sampleAreaLight(const SceneView& sc, Vec2f u2, Vec2f u, float* pmf, Vec3f* p, Vec3f* n,
                                              Color* Le, float* areaPdf) {
  int li = sc.lightSelect.sample(u2, pmf, nullptr);
  const LightPrim& lp = sc.lights[li];
  sampleLightPrim(sc, lp, u, p, n, Le, areaPdf);
  return lp;
}

}  // namespace envgi
