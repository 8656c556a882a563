// A render split over several executors at once equals the one render, pixel by pixel, up to
// float rounding: with a plain filter and with one whose negative lobes weigh the samples.
#include "render/SplitRender.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <mutex>
#include <stdexcept>

#include "accel/EmbreeAccel.h"
#include "support/BundledScene.h"

using namespace envgi;

namespace {

double largestRelativeDifference(const Image& a, const Image& b) {
  double worst = 0.0;
  for (size_t i = 0; i < a.rgb.size(); ++i)
    worst = std::max(worst, std::abs(double(a.rgb[i]) - double(b.rgb[i])) / std::max(1e-3, std::abs(double(b.rgb[i]))));
  return worst;
}

struct Split {
  Image image;
  std::vector<std::pair<int, int>> ranges;  // each share's, as its preparer saw it
};

Split renderInShares(const Scene& scene, const EmbreeAccel& accel, const RenderOptions& o, int spp, int shares) {
  Split out;
  std::mutex m;
  out.ranges.assign(size_t(shares), {-1, -1});
  RenderStats st;
  out.image = renderSplit(scene.camera.width, scene.camera.height, spp, shares, o,
                          [&](const RenderOptions& share, int i) {
                            {
                              std::lock_guard lock(m);
                              out.ranges[size_t(i)] = {share.firstSample, share.sampleEnd};
                            }
                            RenderOptions one = share;
                            one.threads = 1;
                            return prepareRender(scene, accel, one);
                          },
                          &st);
  EXPECT_EQ(st.sppDone, o.sampleEnd < 0 ? spp : o.sampleEnd);
  return out;
}

}  // namespace

TEST(SplitRender, SharesAddUpToTheOneRender) {
  for (const char* name : {"cornell-box", "buddha"}) {
    Scene scene;
    test::loadBundledSmall(name, 24, IntegratorType::Path, &scene);
    if (std::string(name) == "buddha") scene.camera.filter = makeFilter(FilterType::Mitchell);  // negative lobes
    scene.finalize();
    EmbreeAccel accel(scene);
    RenderOptions o;
    o.spp = 16;
    o.progress = false;
    o.checkpointSeconds = 0.0;
    const Image one = render(scene, accel, o, nullptr);
    const Split split = renderInShares(scene, accel, o, 16, 3);
    EXPECT_EQ(split.ranges, (std::vector<std::pair<int, int>>{{0, 5}, {5, 10}, {10, 16}})) << name;
    EXPECT_LT(largestRelativeDifference(split.image, one), 1e-5) << name;
    // A share of the render split again: samples 4:16 in two.
    o.firstSample = 4, o.sampleEnd = 16;
    const Image part = render(scene, accel, o, nullptr);
    const Split halves = renderInShares(scene, accel, o, 16, 2);
    EXPECT_EQ(halves.ranges, (std::vector<std::pair<int, int>>{{4, 10}, {10, 16}})) << name;
    EXPECT_LT(largestRelativeDifference(halves.image, part), 1e-5) << name;
    EXPECT_GT(largestRelativeDifference(part, one), 1e-3) << name << ": the share is not the whole";
  }
}

TEST(SplitRender, AShareThatFailsFailsTheRender) {
  Scene scene;
  test::loadBundledSmall("cornell-box", 8, IntegratorType::Path, &scene);
  scene.finalize();
  EmbreeAccel accel(scene);
  RenderOptions o;
  o.spp = 4;
  o.progress = false;
  auto prepare = [&](const RenderOptions& share, int i) {
    if (i == 1) throw std::runtime_error("device 1 is gone");
    return prepareRender(scene, accel, share);
  };
  try {
    renderSplit(8, 8, 4, 2, o, prepare, nullptr);
    FAIL() << "a failed share was dropped";
  } catch (const std::runtime_error& e) {
    EXPECT_STREQ(e.what(), "device 1 is gone");
  }
  // More shares than samples: one sample a share.
  const Split split = renderInShares(scene, accel, o, 4, 8);
  EXPECT_EQ(split.ranges.size(), 8u);
  EXPECT_EQ(std::count(split.ranges.begin(), split.ranges.end(), std::pair{-1, -1}), 4);
  std::vector<float> variance;
  o.varianceOut = &variance;
  EXPECT_THROW(renderSplit(8, 8, 4, 2, o, prepare, nullptr), std::runtime_error);
  o.varianceOut = nullptr;
  o.firstSample = 3, o.sampleEnd = 3;
  EXPECT_THROW(renderSplit(8, 8, 4, 2, o, prepare, nullptr), std::runtime_error);
}
