// The photon-map pass whatever traces it: a device that traces several sub-batches at once
// (as the GPU does) fills the same maps as the CPU's one at a time, and the GPU's body over the
// GPU's BVH (run here on the CPU) stores what Embree's does.
#include <gtest/gtest.h>

#include "accel/Bvh.h"
#include "render/Cancellation.h"
#include "render/PhotonShooter.h"
#include "scene/SceneLoader.h"
#include "support/CausticScene.h"
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

// The caustic map alone, 40,000 photons asked, aimed or not: its photons' luminous power
// summed (and squared) into the bins binOf(photon) names, below `bins`.
struct BinnedFlux {
  std::vector<double> sum, sumSq;
  PhotonShootStats stats;
};
template <class BinOf>
BinnedFlux shootCausticsBinned(const Scene& s, const EmbreeAccel& accel, bool aim, uint32_t seed, int bins,
                               BinOf binOf) {
  PhotonShootSettings ps;
  ps.globalPhotons = 0;
  ps.causticPhotons = 40000;
  ps.seed = seed;
  ps.progress = false;
  ps.aimCaustics = aim;
  PhotonMap g, c;
  BinnedFlux b;
  b.sum.assign(size_t(bins), 0.0);
  b.sumSq.assign(size_t(bins), 0.0);
  shootPhotons(s, accel, ps, &g, &c, &b.stats);
  for (const Photon& ph : c.photons()) {
    int k = binOf(ph);
    if (k < 0 || k >= bins) continue;
    b.sum[size_t(k)] += luminance(ph.power);
    b.sumSq[size_t(k)] += sqr(double(luminance(ph.power)));
  }
  return b;
}

// Each bin's flux, aimed against unaimed, agrees within 4 sigma (each photon's power counted
// as independent); binsMustHoldLight: every aimed bin holds some.
void expectTheSameFluxInEachBin(const BinnedFlux& aimed, const BinnedFlux& unaimed, const char* bin,
                                bool binsMustHoldLight) {
  for (size_t k = 0; k < aimed.sum.size(); ++k) {
    double sigma = std::sqrt(aimed.sumSq[k] + unaimed.sumSq[k]);
    std::printf("%s %zu: aimed %.4f, unaimed %.4f (sigma %.4f)\n", bin, k, aimed.sum[k], unaimed.sum[k], sigma);
    if (binsMustHoldLight) {
      EXPECT_GT(aimed.sum[k], 0.0) << bin << " " << k;
    }
    EXPECT_NEAR(aimed.sum[k], unaimed.sum[k], 4.0 * sigma + 1e-9) << bin << " " << k;
  }
}

// Caustic photons stored an emitted photon.
double yield(const BinnedFlux& b) { return double(b.stats.storedCaustic) / double(b.stats.emittedCaustic); }

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

// The caustic map from photons aimed at the glass ball holds what the unaimed map holds: the
// flux stored in each ring about the caustic's centre agrees within 4 sigma, while the aimed
// stream stores over 20 times as many caustic photons an emitted photon (the unaimed one stops
// at the pass's cap, 64 times the count).
TEST(PhotonShooter, AimedCausticMapHoldsTheUnaimedFlux) {
  test::CausticSetup cs = test::causticScene(8);
  Scene& s = *cs.scene;
  EmbreeAccel accel(s);
  const float rings[] = {0.f, 0.25f, 0.6f, 1.2f, 2.5f, 1e9f};
  auto ring = [&](const Photon& ph) {
    float d = length(ph.p - cs.causticCentre);
    for (int k = 0; k < 5; ++k)
      if (d >= rings[k] && d < rings[k + 1]) return k;
    return -1;
  };
  BinnedFlux aimed = shootCausticsBinned(s, accel, true, 3, 5, ring);
  BinnedFlux unaimed = shootCausticsBinned(s, accel, false, 3, 5, ring);
  EXPECT_EQ(aimed.stats.causticTargets, 1);
  EXPECT_EQ(unaimed.stats.causticTargets, 0);
  EXPECT_GE(aimed.stats.storedCaustic, 40000u);
  std::printf("caustic photons stored an emitted photon: aimed %.4f, unaimed %.5f\n", yield(aimed), yield(unaimed));
  EXPECT_GT(yield(aimed), 20.0 * yield(unaimed));
  expectTheSameFluxInEachBin(aimed, unaimed, "ring", true);
}

// Caustic photons are aimed only where it pays: at the teapot scene's two glass balls (lit by a
// map), the Cornell box's two balls (lit by an area light) or a mirror ball under a point light,
// not at a mirror floor as wide as the scene.
TEST(PhotonShooter, AimsOnlyAtSmallTargets) {
  Scene teapot, cornell;
  loadScene(std::string(ENVGI_SOURCE_DIR) + "/scenes/teapot-glass.xml", {}, teapot);
  loadScene(std::string(ENVGI_SOURCE_DIR) + "/scenes/cornell-box.xml", {}, cornell);
  teapot.finalize();
  cornell.finalize();
  PhotonEmitter e = makePhotonEmitter(teapot, true);
  ASSERT_EQ(e.targetCount, 2);
  EXPECT_FLOAT_EQ(e.targets[1].cdf, 1.f);
  EXPECT_NEAR(e.targets[0].radius, 1.2f, 0.01f);  // the larger ball, first in the file
  EXPECT_EQ(makePhotonEmitter(cornell, true).targetCount, 2);
  EXPECT_EQ(makePhotonEmitter(teapot).targetCount, 0);  // not asked to aim: SPPM's, a radius
  Bsdf ball, mirror;
  mirror.type = BsdfType::Conductor;
  mirror.perfectMirror = true;
  Image sky(8, 4);
  for (float& v : sky.rgb) v = 1.f;
  auto wide = test::sphereOnFloor(mirror, ball, 8.f, sky, Vec3f(0, 2, 5), Vec3f(0, 0, 0), 8, 40.f);
  EXPECT_EQ(makePhotonEmitter(*wide, true).targetCount, 0);
  // The same mirror as a ball on a wide diffuse floor is aimed at.
  auto small = test::sphereOnFloor(ball, mirror, 8.f, std::move(sky), Vec3f(0, 2, 5), Vec3f(0, 0, 0), 8, 40.f);
  EXPECT_EQ(makePhotonEmitter(*small, true).targetCount, 1);
  // Lit by a point light alone, it is aimed at too.
  small->env.reset();
  small->deltaLights = {DeltaLight{Vec3f(0.f, 4.f, 0.f), Color(1.f), true}};
  small->finalize();
  EXPECT_EQ(makePhotonEmitter(*small, true).targetCount, 1);
}

// The Cornell box's caustic map from photons aimed from its area light at the two balls holds
// what the unaimed map holds: the flux stored on the floor, in a 4 x 4 grid of cells, and on
// the walls and ceiling agrees within 4 sigma.
TEST(PhotonShooter, AreaLightsAimedCausticMapHoldsTheUnaimedFlux) {
  Scene s;
  loadScene(std::string(ENVGI_SOURCE_DIR) + "/scenes/cornell-box.xml", {}, s);
  s.finalize();
  EmbreeAccel accel(s);
  constexpr int kBins = 17;  // 16 floor cells, then everything off the floor
  auto cell = [](const Photon& ph) {
    if (!(ph.p.y < 1e-3f)) return kBins - 1;
    return clampi(int((ph.p.x + 1.f) * 2.f), 0, 3) * 4 + clampi(int((ph.p.z + 1.f) * 2.f), 0, 3);
  };
  BinnedFlux aimed = shootCausticsBinned(s, accel, true, 5, kBins, cell);
  BinnedFlux unaimed = shootCausticsBinned(s, accel, false, 5, kBins, cell);
  EXPECT_EQ(aimed.stats.causticTargets, 2);
  EXPECT_GE(aimed.stats.storedCaustic, 40000u);
  std::printf("caustic photons stored an emitted photon: aimed %.4f, unaimed %.5f\n", yield(aimed), yield(unaimed));
  EXPECT_GT(yield(aimed), 5.0 * yield(unaimed));
  expectTheSameFluxInEachBin(aimed, unaimed, "bin", false);
}

// Ctrl-C during the photon pass (the flag set) ends it with RenderCancelled, maps unfilled.
TEST(PhotonShooter, CancelEndsThePass) {
  test::CausticSetup cs = test::causticScene(8);
  EmbreeAccel accel(*cs.scene);
  std::atomic<bool> cancel{true};
  PhotonShootSettings ps;
  ps.progress = false;
  ps.cancel = &cancel;
  PhotonMap g, c;
  EXPECT_THROW(shootPhotons(*cs.scene, accel, ps, &g, &c, nullptr), RenderCancelled);
  EXPECT_EQ(g.size() + c.size(), 0u);
}

// Maps that could never fit are refused before a photon is shot, naming the count and memory.
TEST(PhotonShooter, MapsThatCannotFitAreRefused) {
  try {
    requirePhotonMapsFit(2000000000, 25.3e9);
    FAIL() << "two billion photons were accepted on a 25.3 GB machine";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("photon maps of 2000000000 photons would take about"), std::string::npos)
        << e.what();
    EXPECT_NE(std::string(e.what()).find("more than half of this machine's 25.3 GB"), std::string::npos) << e.what();
  }
  EXPECT_NO_THROW(requirePhotonMapsFit(500000, 25.3e9));
  EXPECT_NO_THROW(requirePhotonMapsFit(2000000000, 0.0));  // memory unknown
}
