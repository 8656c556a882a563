// SampleLanes makes a round's camera samples lane by lane: the rays, filter weights and sampler
// positions must be the one-sample path's (Sampler::startPixel, then sampleCameraRay) to the
// bit, whatever the camera, filter or sample count.
#include <gtest/gtest.h>

#include <cstring>

#include "wavefront/SampleLanes.h"
#include "wavefront/HostStages.h"

using namespace envgi;

namespace {

bool sameBits(float a, float b) { return std::memcmp(&a, &b, sizeof(float)) == 0; }

Camera testCamera(int w, int h) {
  Camera c;
  c.width = w;
  c.height = h;
  c.tanHalfY = std::tan(0.5f * 35.f * kPi / 180.f);
  c.tanHalfX = c.tanHalfY * float(w) / float(h);
  c.nearClip = 0.03f;
  c.farClip = 800.f;
  c.toWorld = lookAt(Vec3f(1.f, 2.f, 6.f), Vec3f(0.f, 0.5f, 0.f), Vec3f(0.2f, 1.f, 0.f));
  return c;
}

// Every sample of a 37 x 23 image (lanes not a multiple of any vector width) both ways.
void expectSameSamples(const Camera& cam, uint32_t spp, uint32_t seed, const char* what) {
  SampleLanes cr;
  SampleSequence seq{SamplerType::Sobol, spp, seed};
  int mismatches = 0;
  for (uint32_t s = 0; s < spp; ++s) {
    Sampler first = sequenceSampler(seq);
    first.setIndex(s);
    const int n = cam.width * cam.height;
    cr.resize(size_t(n));
    for (int i = 0; i < n; ++i) cr.px[i] = i % cam.width, cr.py[i] = i / cam.width;
    cr.make(cam, first, n);
    for (int i = 0; i < n; ++i) {
      Sampler one = sequenceSampler(seq);
      float w;
      const Ray r = startCameraSample(cam, one, cr.px[i], cr.py[i], int(s), &w);
      Sampler lanes = first;
      lanes.startPixelAt(cr.hash[i], SampleLanes::dimensions(cam));
      const Ray q = cr.rayOf(i);
      const bool same = sameBits(r.o.x, q.o.x) && sameBits(r.o.y, q.o.y) && sameBits(r.o.z, q.o.z) &&
                        sameBits(r.d.x, q.d.x) && sameBits(r.d.y, q.d.y) && sameBits(r.d.z, q.d.z) &&
                        sameBits(r.tMax, q.tMax) && sameBits(w, cr.weight[i]) && one.pixelHash == lanes.pixelHash &&
                        one.dim == lanes.dim;
      // The sampler goes on from the same place: its next draws are the same.
      const Vec2f a = one.get2D(), b = lanes.get2D();
      if (!same || !sameBits(a.x, b.x) || !sameBits(a.y, b.y)) ++mismatches;
    }
  }
  EXPECT_EQ(mismatches, 0) << what << ", spp " << spp;
}

}  // namespace

TEST(SampleLanes, SamplesAreTheOneSamplePathsToTheBit) {
  for (uint32_t spp : {1u, 8u, 6u}) {
    Camera pinhole = testCamera(37, 23);
    pinhole.filter = makeFilter(FilterType::Box);
    expectSameSamples(pinhole, spp, 0, "pinhole, box");
    expectSameSamples(pinhole, spp, 77, "pinhole, box, seed 77");
    pinhole.filter = makeFilter(FilterType::Gaussian);
    expectSameSamples(pinhole, spp, 3, "pinhole, gaussian");
    pinhole.filter = makeFilter(FilterType::Mitchell);
    expectSameSamples(pinhole, spp, 3, "pinhole, mitchell");
    Camera crop = testCamera(37, 23);
    crop.filmWidth = 100, crop.filmHeight = 60, crop.cropX = 31, crop.cropY = 17;
    expectSameSamples(crop, spp, 5, "a crop window");
    Camera lens = testCamera(37, 23);
    lens.apertureRadius = 0.1f;
    lens.focusDistance = 5.f;
    expectSameSamples(lens, spp, 9, "a thin lens");
    Camera ortho = testCamera(37, 23);
    ortho.orthographic = true;
    expectSameSamples(ortho, spp, 11, "orthographic");
  }
}
