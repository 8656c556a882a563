// Runs the host/device sampling and texture code in CUDA kernels and compares it with the CPU.
// Without a GPU it only proves that the code compiles for the device (exit 77 = skipped).
#include <cuda_runtime.h>

#include <cstdio>
#include <stdexcept>
#include <string>
#include <vector>

#include "envmap/EnvironmentMap.h"
#include "gpu/DeviceScene.h"
#include "materials/BsdfFactory.h"
#include "integrators/DirectIntegrator.h"
#include "integrators/PathIntegrator.h"
#include "sampling/Mis.h"
#include "sampling/Sampler.h"

using namespace envgi;

struct CheckResult {
  Vec3f dir;
  Color radiance;
  float pdf;
  float pdfEval;
  float mis;
};

// Coordinates over [-1.5, 2.5)^2: every wrap mode's folds, on host and device alike.
ENVGI_INLINE Vec2f textureCheckUv(int i) {
  return {-1.5f + 4.f * float(i % 97) / 97.f, -1.5f + 4.f * float((i / 97) % 89) / 89.f};
}

__global__ void envmapKernel(EnvironmentMapView env, int n, CheckResult* out) {
  int i = blockIdx.x * blockDim.x + threadIdx.x;
  if (i >= n) return;
  Sampler smp;
  smp.type = SamplerType::Sobol;
  smp.spp = uint32_t(n);
  smp.seed = 7;
  smp.start(0, uint32_t(i));
  EnvStrategy s = EnvStrategy(i % 5);
  EnvSample es = env.sample(s, smp.get2D(), Vec3f(0.f, 1.f, 0.f));
  float counts[2] = {1.f, 1.f};
  float pdfs[2] = {es.pdf, env.pdf(EnvStrategy::Uniform, es.dir)};
  out[i] = {es.dir, es.radiance, es.pdf, env.pdf(s, es.dir, Vec3f(0.f, 1.f, 0.f)),
            misWeight(0, counts, pdfs, 2, 2.f)};
}

// Every BSDF (both microfacet distributions) evaluated and sampled, and camera rays generated:
// run on the device and on the host, to be compared.
// coat: a rough plastic's tables over all roughnesses (device or host copy, as the caller
// runs), which every other rough plastic case reads.
// Each of Mitsuba's six pixel filters, for the camera's draws.
struct FilterSet {
  ReconstructionFilter f[6];
};

ENVGI_HD float bsdfCameraValue(const Camera& cam, const FilterSet& filters, int i, const float* coat) {
  Pcg32 rng(uint64_t(i), 3u);
  Bsdf b;
  b.type = BsdfType(i % 8);
  b.alpha = 0.3f;
  b.twoSided = (i / 8) % 2 == 1;
  b.distribution = MicrofacetType((i / 16) % 2);
  if ((i / 32) % 2 == 1) b.alphaV = 0.05f;  // anisotropic
  if (b.type == BsdfType::RoughPlastic && (i / 64) % 2 == 1) {
    setBsdfCoatTable(b, coat);
    b.coatNodes = kCoatAlphaNodes;
  }
  if ((i / 128) % 2 == 1) {  // under a normal map (texture 0 is never read here: bsdfAt is not called)
    b.normalMapTexture = 0;
    b.mappedNormal = normalize(Vec3f(0.4f, -0.3f, 0.85f));
  }
  if ((i / 256) % 4 == 1) {  // Mitsuba's principled, every lobe on: glass, metal, clearcoat, sheen
    b.type = BsdfType::Principled;
    b.reflectance = Color(0.8f, 0.5f, 0.2f);
    PrincipledParams& p = b.principled;
    p.roughness = 0.2f + 0.1f * float(i % 5), p.metallic = 0.3f, p.specTrans = 0.4f, p.clearcoat = 0.5f;
    p.sheen = 0.5f, p.flatness = 0.5f, p.specTint = 0.3f, p.anisotropic = 0.4f * float((i / 32) % 2);
  }
  Vec3f wo = normalize(Vec3f(0.3f, 0.2f, (i % 3 == 0) ? -0.8f : 0.8f));
  // Draws into named values: the order in which a call's arguments are evaluated is the
  // compiler's choice, and g++ and nvcc's device side choose differently.
  float u[5];
  for (float& x : u) x = rng.nextFloat();
  BsdfSample bs;
  float acc = 0.f;
  if (bsdfSample(b, wo, u[0], Vec2f(u[1], u[2]), &bs))
    acc = bs.weight.y + bsdfEval(b, wo, bs.wi).x + bsdfPdf(b, wo, bs.wi);
  Ray r = cam.generateRay(float(i % cam.width) + 0.5f, float((i / cam.width) % cam.height) + 0.5f);
  FilterSample fs = sampleFilter(filters.f[i % 6], Vec2f(u[3], u[4]));
  return acc + r.d.z + fs.offset.x + fs.offset.y + fs.weight;
}
__global__ void bsdfCameraKernel(Camera cam, FilterSet filters, int n, const float* coat, float* out) {
  int i = blockIdx.x * blockDim.x + threadIdx.x;
  if (i < n) out[i] = bsdfCameraValue(cam, filters, i, coat);
}

// Textures looked up on the device, for comparison with the same lookups on the host.
__global__ void textureKernel(const TextureView* tex, int count, int n, Color* out) {
  int i = blockIdx.x * blockDim.x + threadIdx.x;
  if (i >= n) return;
  out[i] = textureEval(tex[i % count], textureCheckUv(i));
}

// A brute-force sphere tracer: enough to instantiate the integrators in device code.
struct SphereTracer {
  const SceneView* sc;
  ENVGI_HD bool intersect(const Ray& r, Hit* h) const {
    bool found = false;
    for (int i = 0; i < sc->sphereCount; ++i) {
      Vec3f oc = r.o - sc->spheres[i].center;
      float b = dot(oc, r.d), c = dot(oc, oc) - sqr(sc->spheres[i].radius), disc = b * b - c;
      if (disc < 0.f) continue;
      float sq = std::sqrt(disc);
      float t = -b - sq > 0.f ? -b - sq : -b + sq;
      if (t > 0.f && t < r.tMax && t < h->t) {
        h->t = t;
        h->geomId = sc->meshCount + i;
        h->primId = 0;
        found = true;
      }
    }
    return found;
  }
  ENVGI_HD bool occluded(Vec3f o, Vec3f d, float tMax) const {
    Hit h;
    return intersect(Ray{o, d, tMax}, &h);
  }
};

__global__ void integratorKernel(SceneView sc, int n, Color* out) {
  int i = blockIdx.x * blockDim.x + threadIdx.x;
  if (i >= n) return;
  SphereTracer tr{&sc};
  Sampler smp;
  smp.spp = 1;
  smp.start(uint64_t(i), 0);
  uint64_t rays = 0;
  Ray ray = sc.camera.generateRay(float(i % sc.camera.width) + 0.5f, float(i / sc.camera.width) + 0.5f);
  out[i] = (i % 2) ? pathTrace(sc, tr, ray, smp, PathParams{}, &rays) : directTrace(sc, tr, ray, smp, DirectParams{}, &rays);
}

// A launch that failed (too many registers, no image for this GPU) leaves its output unwritten:
// say so, rather than compare whatever the memory held.
static void checkLaunch(const char* kernel) {
  cudaError_t e = cudaGetLastError();
  if (e != cudaSuccess) throw std::runtime_error(std::string(kernel) + " did not launch: " + cudaGetErrorString(e));
}

int main() try {
  gpu::DeviceArena arena;
  int devices = 0;
  if (cudaGetDeviceCount(&devices) != cudaSuccess || devices == 0) {
    std::printf("envgi_cuda_check: no CUDA device; kernels compiled and linked only\n");
    return 77;
  }
  // A synthetic map with a bright spot, so every strategy has structure to follow.
  Image img(64, 32);
  for (int y = 0; y < 32; ++y)
    for (int x = 0; x < 64; ++x) img.set(x, y, Color(0.1f + 0.01f * x, 0.2f, 0.05f * y + ((x == 40 && y == 9) ? 500.f : 0.f)));
  EnvironmentMap env(std::move(img), {});
  const int n = 1 << 16;
  CheckResult* dOut = nullptr;
  cudaMalloc(&dOut, sizeof(CheckResult) * n);
  envmapKernel<<<(n + 255) / 256, 256>>>(gpu::uploadEnvironment(arena, env.view()), n, dOut);
  checkLaunch("envmapKernel");
  std::vector<CheckResult> gpu(n);
  cudaError_t err = cudaMemcpy(gpu.data(), dOut, sizeof(CheckResult) * n, cudaMemcpyDeviceToHost);
  if (err != cudaSuccess) {
    std::printf("envgi_cuda_check: CUDA error %s\n", cudaGetErrorString(err));
    return 1;
  }
  // The same computation on the CPU, launched as a plain loop.
  EnvironmentMapView host = env.view();
  int mismatches = 0;
  double maxRel = 0.0;
  for (int i = 0; i < n; ++i) {
    Sampler smp;
    smp.type = SamplerType::Sobol;
    smp.spp = uint32_t(n);
    smp.seed = 7;
    smp.start(0, uint32_t(i));
    EnvStrategy s = EnvStrategy(i % 5);
    EnvSample es = host.sample(s, smp.get2D(), Vec3f(0.f, 1.f, 0.f));
    double rel = std::fabs(es.pdf - gpu[i].pdf) / std::max(1e-6f, es.pdf);
    maxRel = std::max(maxRel, rel);
    if (rel > 1e-3 || length(es.dir - gpu[i].dir) > 1e-3f) ++mismatches;
  }
  // BSDFs and camera rays.
  Camera cam;
  cam.width = cam.height = 64;
  cam.tanHalfX = cam.tanHalfY = 0.5f;
  FilterSet filters;
  for (int k = 0; k < 6; ++k) filters.f[k] = makeFilter(FilterType(k));
  float* dB = nullptr;
  cudaMalloc(&dB, sizeof(float) * n);
  int coatNodes = 0;
  const float* coat = roughCoatTable(0.f, 1.49f, MicrofacetType::GGX, true, &coatNodes);
  float* dCoat = nullptr;
  cudaMalloc(&dCoat, sizeof(float) * coatNodes * kCoatStride);
  cudaMemcpy(dCoat, coat, sizeof(float) * coatNodes * kCoatStride, cudaMemcpyHostToDevice);
  bsdfCameraKernel<<<(n + 255) / 256, 256>>>(cam, filters, n, dCoat, dB);
  checkLaunch("bsdfCameraKernel");
  std::vector<float> bres(n);
  cudaMemcpy(bres.data(), dB, sizeof(float) * n, cudaMemcpyDeviceToHost);
  int bad = 0, bsdfMismatches = 0;
  for (int i = 0; i < n; ++i) {
    bad += !std::isfinite(bres[i]);
    float h = bsdfCameraValue(cam, filters, i, coat);
    // Device exp, log and erf differ from the host's by ulps, which a sample may amplify.
    if (std::fabs(h - bres[i]) > 1e-3f * fmaxf(1.f, std::fabs(h)) && ++bsdfMismatches <= 5)
      std::printf("envgi_cuda_check: BSDF/camera case %d (type %d): CPU %.7g, GPU %.7g\n", i, i % 8, h, bres[i]);
  }
  std::printf("envgi_cuda_check: %d BSDF and camera values, %d differ from the CPU's\n", n, bsdfMismatches);
  // Textures: a 5x3 bitmap with each wrap mode and filter, and a checkerboard.
  std::vector<Color> texels;
  for (int k = 0; k < 15; ++k) texels.push_back(Color(float(k % 5), float(k / 5), 0.1f * float(k)));
  const Color* dTexels = arena.upload(texels.data(), texels.size(), "texels");
  std::vector<TextureView> views;
  for (TextureWrap w : {TextureWrap::Repeat, TextureWrap::Mirror, TextureWrap::Clamp})
    for (bool bilinear : {true, false}) {
      TextureView t;
      t.texels = texels.data();
      t.width = 5;
      t.height = 3;
      t.wrap = w;
      t.bilinear = bilinear;
      t.toUv[1] = 0.3f;  // a shear, so that to_uv counts too
      views.push_back(t);
    }
  TextureView checks;
  checks.type = TextureType::Checkerboard;
  checks.toUv[0] = 3.f;
  views.push_back(checks);
  std::vector<TextureView> deviceViews = views;
  for (TextureView& t : deviceViews)
    if (t.texels) t.texels = dTexels;
  const TextureView* dViews = arena.upload(deviceViews.data(), deviceViews.size(), "textures");
  Color* dT = arena.allocate<Color>(size_t(n), "texture results");
  textureKernel<<<(n + 255) / 256, 256>>>(dViews, int(views.size()), n, dT);
  checkLaunch("textureKernel");
  std::vector<Color> tres(n);
  cudaMemcpy(tres.data(), dT, sizeof(Color) * n, cudaMemcpyDeviceToHost);
  int textureMismatches = 0;
  for (int i = 0; i < n; ++i) {
    Color want = textureEval(views[size_t(i) % views.size()], textureCheckUv(i));
    textureMismatches += length(want - tres[size_t(i)]) > 1e-5f * (1.f + length(want));
  }
  std::printf("envgi_cuda_check: %d texture lookups, %d differ from the CPU's\n", n, textureMismatches);
  bad += textureMismatches;
  // The integrators on a two-sphere scene lit by the same map, the ground textured.
  SceneView sv;
  SphereView spheres[2] = {{Vec3f(0.f, 0.f, -3.f), 1.f, 0, -1, false}, {Vec3f(0.f, -101.f, -3.f), 100.f, 1, -1, false}};
  Bsdf bsdfs[2];
  bsdfs[0].type = BsdfType::RoughConductor;
  bsdfs[0].perfectMirror = true;
  bsdfs[0].alpha = 0.2f;
  sv.spheres = arena.upload(spheres, 2, "spheres");
  sv.sphereCount = 2;
  bsdfs[1].reflectanceTexture = int(views.size()) - 1;
  bsdfs[0].alphaTexture = 0;  // anisotropic, both roughnesses textured
  bsdfs[0].alphaV = 0.1f;
  bsdfs[0].alphaVTexture = 0;
  sv.bsdfs = arena.upload(bsdfs, 2, "materials");
  sv.textures = dViews;
  sv.hasEnvironment = true;
  sv.env = gpu::uploadEnvironment(arena, env.view());
  sv.camera = cam;
  Color* dC = nullptr;
  const int m = 64 * 64;
  cudaMalloc(&dC, sizeof(Color) * m);
  integratorKernel<<<(m + 127) / 128, 128>>>(sv, m, dC);
  checkLaunch("integratorKernel");
  std::vector<Color> cres(m);
  err = cudaMemcpy(cres.data(), dC, sizeof(Color) * m, cudaMemcpyDeviceToHost);
  for (const Color& c : cres) bad += !isFiniteVec(c);
  std::printf("envgi_cuda_check: BSDF/camera/integrator kernels: %d non-finite results, %s\n", bad,
              cudaGetErrorString(err));
  cudaFree(dB);
  cudaFree(dCoat);
  cudaFree(dC);
  cudaFree(dOut);
  if (bad > 0 || err != cudaSuccess) return 1;
  std::printf("envgi_cuda_check: %d samples, %d mismatches against the CPU, max pdf rel. diff %.3g\n", n, mismatches,
              maxRel);
  return mismatches <= n / 1000 && bsdfMismatches <= n / 1000 ? 0 : 1;
} catch (const std::exception& e) {
  std::printf("envgi_cuda_check: %s\n", e.what());
  return 1;
}
