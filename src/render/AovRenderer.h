// The AOVs (scene/Aov.h) of a scene's camera: what each pixel's first hits are, averaged over a
// few camera samples a pixel with the film's filter weights, as extra image channels. They need
// only the camera's rays, so they are traced on the CPU whichever device renders the image.
#pragma once

#include <vector>

#include "accel/EmbreeAccel.h"
#include "image/Image.h"
#include "scene/Aov.h"
#include "scene/Scene.h"

namespace envgi {

// Camera samples a pixel the AOVs take at most: enough to antialias edges; more only costs.
inline constexpr int kAovMaxSamples = 16;
// BSDF samples a hit's albedo (its directional albedo towards the camera) is estimated from.
inline constexpr int kAovAlbedoSamples = 4;

// The channels of scene.aovs, in order (aovChannelNames), over the camera's film: `samples`
// camera samples a pixel (at most kAovMaxSamples). A pixel whose rays miss everything reads 0,
// or -1 for the two indices; alpha (the film's A) is 1 where the environment is seen, else the
// share of the rays that met a surface. threads 0: all cores.
std::vector<ImageChannel> renderAovs(const Scene& scene, const EmbreeAccel& accel, int samples, int threads);

}  // namespace envgi
