// No heap allocation inside the per-ray path (docs/architecture.md): a pass's allocations are
// counted by replacing the global operator new in this test's own program, and must not grow
// with the rays it traces. Its own executable, so that the replacement touches no other test;
// not built under the sanitizers, which bring their own allocator.
#include <gtest/gtest.h>

#include <atomic>
#include <cstdio>
#include <cstdlib>
#include <new>

#include "accel/EmbreeAccel.h"
#include "render/Progress.h"
#include "render/Renderer.h"
#include "scene/NameTables.h"
#include "support/BundledScene.h"
#include "support/SmallGrid.h"

namespace {
std::atomic<uint64_t> gAllocations{0};
}  // namespace

void* operator new(std::size_t n) {
  gAllocations.fetch_add(1, std::memory_order_relaxed);
  if (void* p = std::malloc(n ? n : 1)) return p;
  throw std::bad_alloc();
}
void* operator new[](std::size_t n) { return operator new(n); }
void* operator new(std::size_t n, std::align_val_t a) {
  gAllocations.fetch_add(1, std::memory_order_relaxed);
  std::size_t al = std::size_t(a);
  if (void* p = std::aligned_alloc(al, (n + al - 1) / al * al)) return p;
  throw std::bad_alloc();
}
void* operator new[](std::size_t n, std::align_val_t a) { return operator new(n, a); }
void operator delete(void* p) noexcept { std::free(p); }
void operator delete[](void* p) noexcept { std::free(p); }
void operator delete(void* p, std::size_t) noexcept { std::free(p); }
void operator delete[](void* p, std::size_t) noexcept { std::free(p); }
void operator delete(void* p, std::align_val_t) noexcept { std::free(p); }
void operator delete[](void* p, std::align_val_t) noexcept { std::free(p); }
void operator delete(void* p, std::size_t, std::align_val_t) noexcept { std::free(p); }
void operator delete[](void* p, std::size_t, std::align_val_t) noexcept { std::free(p); }

using namespace envgi;

// Each integrator with a per-sample kernel, on scenes that reach its materials and lights: a
// pass of 4 samples a pixel on one thread, after a first pass that warms what is made once.
TEST(NoAllocationPerRay, APassAllocatesPerTileAtMost) {
  struct Case {
    const char* scene;
    const char* integrator;
  };
  for (Case c : {Case{"buddha", "path"}, Case{"teapot-glass", "path"}, Case{"textured", "path"},
                 Case{"sun-and-sky", "path"}, Case{"cornell-box", "path"}, Case{"buddha", "direct"},
                 Case{"cornell-box", "photon"}, Case{"teapot-glass", "photon"}, Case{"buddha", "grid"}}) {
    Scene s;
    test::loadBundledSmall(c.scene, 32, findIntegrator(c.integrator), &s);
    if (s.integrator.type == IntegratorType::Photon) {
      s.integrator.photon.globalPhotons = 20000;
      s.integrator.photon.causticPhotons = 20000;
    }
    test::useSmallGrid(s.integrator.grid);
    s.finalize();
    EmbreeAccel accel(s);
    RenderOptions o;
    o.progress = false;
    o.threads = 1;
    o.spp = 8;
    PreparedRender pr = prepareRender(s, accel, o);
    Progress quiet(1, false);
    PassCounters warm, counters;
    pr.executor->runPass(0, 4, quiet, &warm);
    uint64_t before = gAllocations.load();
    pr.executor->runPass(4, 8, quiet, &counters);
    uint64_t allocations = gAllocations.load() - before;
    std::printf("%-12s %-6s %llu rays, %llu allocations in the pass\n", c.scene, c.integrator,
                (unsigned long long)counters.rays, (unsigned long long)allocations);
    EXPECT_GT(counters.rays, 32u * 32u * 4u);
    // 32 x 32 pixels are a handful of tiles; one allocation a ray would be thousands.
    EXPECT_LT(allocations, 64u) << c.scene << " " << c.integrator;
  }
}
