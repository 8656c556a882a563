// The scene and its BVH copied to a GPU: the same plain views the CPU reads, with device
// pointers. CUDA-only (included from .cu files).
#pragma once

#include "accel/Bvh.h"
#include "gpu/DeviceMemory.h"
#include "scene/Scene.h"

namespace envgi::gpu {

// The environment map's texels and sampling tables on the device.
EnvironmentMapView uploadEnvironment(DeviceArena& arena, EnvironmentMapView v);

struct DeviceScene {
  DeviceArena arena;
  SceneView view;                   // device pointers inside, the struct itself on the host
  const SceneView* deviceView = nullptr;  // the same struct in device memory
  BvhView bvh;

  DeviceScene(const Scene& scene, const Bvh& bvh);
};

}  // namespace envgi::gpu
