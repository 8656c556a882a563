// The photon-map pass whatever traces it: a device that traces several sub-batches at once
// (as the GPU does) fills the same maps as the CPU's one at a time, and the GPU's body over the
// GPU's BVH (run here on the CPU) stores what Embree's does.
#include <gtest/gtest.h>

#include "accel/Bvh.h"
#include "render/PhotonShooter.h"
#include "scene/SceneLoader.h"
#include "support/TestScenes.h"

using namespace envgi;

namespace {

// The CPU tracer, asked for `n` sub-batches at a time.
class WideTracer final : public PhotonBatchTracer {
 public:
  WideTracer(std::unique_ptr<PhotonBatchTracer> inner, int n) : inner_(std::move(inner)), n_(n) {}
  std::string deviceName() const override { return "wide"; }
  int subBatchesPerCall() const override { return n_; }
  void trace(const PhotonTraceRequest& r, std::vector<PhotonBatch>* out) override {
    out->clear();
    for (int b = 0; b < n_; ++b) {
      PhotonTraceRequest rb = r;
      rb.first = r.first + uint64_t(b) * kPhotonSubBatch;
      std::vector<PhotonBatch> one;
      inner_->trace(rb, &one);
      out->push_back(std::move(one.at(0)));
    }
  }

 private:
  std::unique_ptr<PhotonBatchTracer> inner_;
  int n_;
};

struct Maps {
  PhotonMap global, caustic;
  PhotonShootStats stats;
};

void shoot(const Scene& s, const EmbreeAccel& accel, std::shared_ptr<PhotonBatchTracer> tracer, Maps* m) {
  PhotonShootSettings ps;
  ps.globalPhotons = 60000;
  ps.causticPhotons = 20000;
  ps.seed = 5;
  ps.progress = false;
  ps.tracer = std::move(tracer);
  shootPhotons(s, accel, ps, &m->global, &m->caustic, &m->stats);
}

double power(const PhotonMap& m) {
  double p = 0.0;
  for (const Photon& ph : m.photons()) p += luminance(ph.power);
  return p;
}

}  // namespace

TEST(PhotonShooter, SubBatchesPerCallDoNotChangeTheMaps) {
  Scene s;
  loadScene(std::string(ENVGI_SOURCE_DIR) + "/scenes/teapot-glass.xml", {}, s);
  s.finalize();
  EmbreeAccel accel(s);
  Maps one, wide;
  shoot(s, accel, nullptr, &one);
  shoot(s, accel, std::make_shared<WideTracer>(makeCpuPhotonTracer(s, accel), 5), &wide);
  EXPECT_EQ(wide.stats.device, "wide");
  ASSERT_EQ(one.global.size(), wide.global.size());
  ASSERT_EQ(one.caustic.size(), wide.caustic.size());
  EXPECT_EQ(one.stats.emittedGlobal, wide.stats.emittedGlobal);
  EXPECT_EQ(one.stats.emittedCaustic, wide.stats.emittedCaustic);
  EXPECT_GT(one.caustic.size(), 0u);
  EXPECT_EQ(power(one.global), power(wide.global));
  EXPECT_EQ(power(one.caustic), power(wide.caustic));
}

TEST(PhotonShooter, GpuBodyOnTheBvhStoresWhatEmbreeDoes) {
  for (std::string name : {"cornell-box", "teapot-glass"}) {
    Scene s;
    loadScene(std::string(ENVGI_SOURCE_DIR) + "/scenes/" + name + ".xml", {}, s);
    s.finalize();
    EmbreeAccel accel(s);
    Bvh bvh(s);
    Maps e, b;
    shoot(s, accel, nullptr, &e);
    shoot(s, accel, makeCpuPhotonTracer(s, bvh.view()), &b);
    EXPECT_EQ(b.stats.device, "cpu (envgi BVH)");
    // The same photons up to a hit rounded differently now and then.
    EXPECT_NEAR(double(b.global.size()) / double(e.global.size()), 1.0, 0.002) << name;
    EXPECT_NEAR(double(b.caustic.size()) / double(e.caustic.size()), 1.0, 0.002) << name;
    EXPECT_NEAR(power(b.global) / power(e.global), 1.0, 0.002) << name;
    EXPECT_NEAR(power(b.caustic) / power(e.caustic), 1.0, 0.002) << name;
  }
}

// A lone floor under a sky: light reaches no second surface, so neither map can hold a photon
// (the global map stores only after a bounce). The pass gives up on each after 2^20 photons,
// as it did on the caustic map, instead of shooting on to the cap, 64 times the count asked.
TEST(PhotonShooter, AMapNothingCanReachStopsAfterAMillionPhotons) {
  Bsdf diffuse;
  auto white = [] {
    Image sky(4, 2);
    for (float& v : sky.rgb) v = 1.f;
    return sky;
  };
  auto s = test::sphereOnFloor(diffuse, diffuse, 10.f, white(), Vec3f(0, 4, 3), Vec3f(0, 0, 0), 8, 30.f);
  s->spheres.clear();
  s->shapes.pop_back();
  s->finalize();
  EmbreeAccel accel(*s);
  Maps m;
  shoot(*s, accel, nullptr, &m);
  EXPECT_EQ(m.stats.storedGlobal, 0u);
  EXPECT_EQ(m.stats.storedCaustic, 0u);
  const uint64_t million = uint64_t(1) << 20;
  EXPECT_EQ(m.stats.emittedGlobal, million);
  EXPECT_EQ(m.stats.emittedCaustic, million);

  // With the ball back, some light bounces between floor and ball: a map that is only sparse
  // goes on filling past 2^20 photons (here to the cap: the ball is small under a wide sky).
  auto lit = test::sphereOnFloor(diffuse, diffuse, 10.f, white(), Vec3f(0, 4, 3), Vec3f(0, 0, 0), 8, 30.f);
  EmbreeAccel litAccel(*lit);
  Maps full;
  shoot(*lit, litAccel, nullptr, &full);
  EXPECT_GT(full.stats.storedGlobal, 0u);
  EXPECT_GT(full.stats.emittedGlobal, 2 * million);
}
