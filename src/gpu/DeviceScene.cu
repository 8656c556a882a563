#include "gpu/DeviceScene.h"

#include <map>
#include <type_traits>

namespace envgi::gpu {

EnvironmentMapView uploadEnvironment(DeviceArena& a, EnvironmentMapView v) {
  size_t px = size_t(v.width) * v.height;
  v.texels = a.upload(v.texels, px * 4, "environment map");
  // The bilinear-matched density's tables and Algorithm 1's own, alike in shape.
  for (PiecewiseConstant2DView* d : {&v.dist, &v.paperDist}) {
    d->condFunc = a.upload(d->condFunc, px, "environment CDFs");
    d->condCdf = a.upload(d->condCdf, size_t(v.height) * (v.width + 1), "environment CDFs");
    d->condInt = a.upload(d->condInt, size_t(v.height), "environment CDFs");
    d->marginal.func = a.upload(d->marginal.func, size_t(v.height), "environment CDFs");
    d->marginal.cdf = a.upload(d->marginal.cdf, size_t(v.height) + 1, "environment CDFs");
  }
  bool sharedEmission = v.emission.bins == v.alias.bins;
  v.alias.bins = a.upload(v.alias.bins, size_t(v.alias.n), "environment alias table");
  v.emission.bins = sharedEmission ? v.alias.bins : a.upload(v.emission.bins, size_t(v.emission.n), "environment emission table");
  v.adaptive.nodes = a.upload(v.adaptive.nodes, size_t(v.adaptive.nodeCount), "adaptive quadtree");
  v.adaptive.leafNodes = a.upload(v.adaptive.leafNodes, size_t(v.adaptive.leafCount), "adaptive quadtree");
  v.points = a.upload(v.points, size_t(v.pointCount), "collapsed map");
  v.warpBits = a.upload(v.warpBits, (px + 31) / 32, "environment warp mask");
  v.adaptive.leafSolidAngle = a.upload(v.adaptive.leafSolidAngle, size_t(v.adaptive.leafCount), "adaptive quadtree");
  if (v.product.valid()) {
    CosineProductView& p = v.product;
    size_t cells = size_t(p.cells()), buckets = size_t(p.bucketsPerSide) * p.bucketsPerSide;
    p.bucketCdf = a.upload(p.bucketCdf, buckets * (cells + 1), "cosine product tables");
    p.bucketInt = a.upload(p.bucketInt, buckets, "cosine product tables");
    p.cellCdf = a.upload(p.cellCdf, px + cells, "cosine product tables");
    p.cellCdfStart = a.upload(p.cellCdfStart, cells, "cosine product tables");
    p.bucketGuide = a.upload(p.bucketGuide, buckets * (p.bucketGuideSize + 1), "cosine product tables");
    p.cellGuide = a.upload(p.cellGuide, cells * (p.cellGuideSize + 1), "cosine product tables");
    // One block on the host (CosineProduct::layout_): upload it once and point into it.
    size_t layout = size_t(p.cellsX + 1 + p.cellsY + 1 + p.width + p.height);
    const int* start = a.upload(p.cellStartX, layout, "cosine product tables");
    p.cellStartY = start + (p.cellStartY - p.cellStartX);
    p.columnCell = start + (p.columnCell - p.cellStartX);
    p.rowCell = start + (p.rowCell - p.cellStartX);
    p.cellStartX = start;
  }
  return v;
}

DeviceScene::DeviceScene(const Scene& scene, const Bvh& hostBvh) {
  const SceneView& hv = scene.view();
  view = hv;
  std::vector<MeshView> meshes(hv.meshes, hv.meshes + hv.meshCount);
  // Instances of one shapegroup mesh point at the same host arrays: each is uploaded once.
  std::map<const void*, const void*> uploaded;
  auto once = [&](auto* host, size_t n, const char* what) {
    using T = std::remove_const_t<std::remove_pointer_t<decltype(host)>>;
    if (!host) return static_cast<const T*>(nullptr);
    auto it = uploaded.find(host);
    if (it == uploaded.end()) it = uploaded.emplace(host, arena.upload(host, n, what)).first;
    return static_cast<const T*>(it->second);
  };
  std::vector<Transform> placements;
  placements.reserve(size_t(hv.meshCount));
  for (int i = 0; i < hv.meshCount; ++i) {
    MeshView& m = meshes[size_t(i)];
    const size_t nv = size_t(m.vertexCount);
    m.positions = once(m.positions, nv, "mesh positions");
    m.normals = once(m.normals, nv, "mesh normals");
    m.uvs = once(m.uvs, nv, "mesh uvs");
    m.indices = once(m.indices, 3 * size_t(m.triangleCount), "mesh indices");
    if (m.toWorld) placements.push_back(*m.toWorld);
  }
  const Transform* deviceTransforms =
      placements.empty() ? nullptr : arena.upload(placements.data(), placements.size(), "instance transforms");
  for (size_t i = 0, k = 0; i < meshes.size(); ++i)
    if (meshes[i].toWorld) meshes[i].toWorld = deviceTransforms + k++;
  view.meshes = arena.upload(meshes.data(), meshes.size(), "meshes");
  view.spheres = arena.upload(hv.spheres, size_t(hv.sphereCount), "spheres");
  // Rough plastics point at their coat's tables on the host: upload each table once.
  std::vector<Bsdf> bsdfs(hv.bsdfs, hv.bsdfs + scene.bsdfs.size());
  std::map<const float*, const float*> coats;
  for (Bsdf& b : bsdfs) {
    const float* table = bsdfCoatTable(b);
    if (b.coatNodes == 0 || !table) continue;
    auto it = coats.find(table);
    if (it == coats.end())
      it = coats.emplace(table, arena.upload(table, size_t(b.coatNodes) * kCoatStride, "rough plastic tables")).first;
    setBsdfCoatTable(b, it->second);
  }
  view.bsdfs = arena.upload(bsdfs.data(), bsdfs.size(), "materials");
  std::vector<TextureView> textures(hv.textures, hv.textures + scene.textures.size());
  for (TextureView& t : textures)
    if (t.texels) t.texels = arena.upload(t.texels, size_t(t.width) * size_t(t.height), "texture texels");
  view.textures = arena.upload(textures.data(), textures.size(), "textures");
  view.lights = arena.upload(hv.lights, size_t(hv.lightCount), "lights");
  view.lightSelect.bins = arena.upload(hv.lightSelect.bins, size_t(hv.lightSelect.n), "light table");
  view.lightCells = arena.upload(hv.lightCells, size_t(hv.lightCellCount), "textured lights' cells");
  view.deltaLights = arena.upload(hv.deltaLights, size_t(hv.deltaLightCount), "delta lights");
  if (hv.hasEnvironment) view.env = uploadEnvironment(arena, hv.env);
  deviceView = arena.upload(&view, 1, "scene");

  BvhView b = hostBvh.view();
  bvh = b;
  bvh.nodes = arena.upload(b.nodes, size_t(b.nodeCount), "BVH nodes");
  bvh.triangles = arena.upload(b.triangles, hostBvh.triangles().size(), "BVH triangles");
  bvh.instances = arena.upload(b.instances, hostBvh.instances().size(), "BVH instances");
  bvh.spheres = view.spheres;
  bvh.masks = hv.hasMasks ? deviceView : nullptr;
}

}  // namespace envgi::gpu
