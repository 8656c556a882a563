// Which sample a pass takes where: the sequence, its seed and spp, and the camera sample that
// starts sample s of a pixel. The same (pixel, sample) gives the same sample on any device and
// in any executor (per pixel, by regeneration or in waves).
#pragma once

#include "sampling/Sampler.h"
#include "scene/Camera.h"

namespace envgi {

struct SampleSequence {
  SamplerType type = SamplerType::Independent;
  uint32_t spp = 1;
  uint32_t seed = 0;
};

// A sampler over the pass's sequence, to be started per sample.
ENVGI_HD inline Sampler sequenceSampler(const SampleSequence& seq) {
  Sampler smp;
  smp.type = seq.type;
  smp.spp = seq.spp;
  smp.seed = seq.seed;
  return smp;
}

// Starts sample s of pixel (x, y): the sampler at its first dimension, the filter offset, the
// camera ray, and the filter's weight for the sample's radiance.
ENVGI_HD inline Ray startCameraSample(const Camera& cam, Sampler& smp, int x, int y, int s, float* weight) {
  smp.start(uint64_t(y) * uint64_t(cam.width) + uint64_t(x), uint32_t(s));
  return sampleCameraRay(cam, smp, x, y, weight);
}

}  // namespace envgi
