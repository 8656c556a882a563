// The render loop's own rules: how renderPasses cuts a render into passes, and the film's
// memory bound.
#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <climits>
#include <thread>

#include "render/Renderer.h"

using namespace envgi;

namespace {

// Records the passes it is asked for; its film stays black.
class RecordingExecutor final : public PassExecutor {
 public:
  RecordingExecutor(int w, int h, double budget) : px_(size_t(w) * size_t(h)), budget_(budget) {}
  std::string deviceName() const override { return "recording"; }
  void runPass(int s0, int s1, Progress&, PassCounters*) override {
    passes.push_back({s0, s1});
    if (cancelAfter && passes.size() == cancelAfterPasses) cancelAfter->store(true);
  }
  void readFilm(FilmSums* out) override { out->sum.assign(px_, Color(0.f)); }
  double maxPassPixelSamples() const override { return budget_; }
  std::vector<std::pair<int, int>> passes;
  std::atomic<bool>* cancelAfter = nullptr;  // set (Ctrl-C) once cancelAfterPasses have run
  size_t cancelAfterPasses = 0;

 private:
  size_t px_;
  double budget_;
};

// Each sample adds radiance 1 to its pixel. Watching Ctrl-C, it raises it itself at the start
// of pass cutAt (a user's Ctrl-C in that pass) and then gives the pass to the first `keep`
// pixels only, as a CPU pass cut between tiles does.
class CuttingExecutor final : public PassExecutor {
 public:
  CuttingExecutor(size_t pixels, size_t cutAt, size_t keep) : sum_(pixels, Color(0.f)), cutAt_(cutAt), keep_(keep) {}
  std::string deviceName() const override { return "cutting"; }
  void watchCancel(const std::atomic<bool>* c) override { watched_ = c; }
  void runPass(int s0, int s1, Progress&, PassCounters*) override {
    took_.clear();
    if (++passes == cutAt_) raise->store(true);
    if (watched_ && watched_->load()) took_.assign(sum_.size(), 0);
    for (size_t i = 0; i < sum_.size(); ++i) {
      if (!took_.empty() && i >= keep_) continue;
      if (!took_.empty()) took_[i] = 1;
      sum_[i] += Color(float(s1 - s0));
    }
  }
  const std::vector<unsigned char>* cutPass() const override { return took_.empty() ? nullptr : &took_; }
  void readFilm(FilmSums* out) override { out->sum = sum_; }
  std::atomic<bool>* raise = nullptr;
  size_t passes = 0;

 private:
  std::vector<Color> sum_;
  size_t cutAt_, keep_;
  const std::atomic<bool>* watched_ = nullptr;
  std::vector<unsigned char> took_;
};

// Passes of one sample, each taking `ms` milliseconds; a black film of 4 pixels.
class SlowExecutor final : public PassExecutor {
 public:
  explicit SlowExecutor(int ms) : ms_(ms) {}
  std::string deviceName() const override { return "slow"; }
  void runPass(int, int, Progress&, PassCounters*) override {
    std::this_thread::sleep_for(std::chrono::milliseconds(ms_));
  }
  void readFilm(FilmSums* out) override { out->sum.assign(4, Color(0.f)); }
  int maxPassSize() const override { return 1; }

 private:
  int ms_;
};

std::vector<std::pair<int, int>> passesOf(int w, int h, int spp, double budget) {
  RecordingExecutor ex(w, h, budget);
  RenderOptions o;
  o.progress = false;
  RenderStats st;
  renderPasses(ex, w, h, spp, o, &st);
  EXPECT_EQ(st.sppDone, spp);
  return ex.passes;
}

using Passes = std::vector<std::pair<int, int>>;

}  // namespace

// Passes double up to 64 samples where the image is small beside the budget; on a larger one
// they stop doubling at the largest power of two whose pass fits in it, and at one sample a
// pass where even that does not. Each pass starts at a multiple of its size, so a checkpoint
// holds whole power-of-two blocks of every pixel's Sobol samples.
TEST(RenderPasses, ALargeImageTakesSmallerPasses) {
  EXPECT_EQ(passesOf(16, 16, 200, 256.0 * 64),
            (Passes{{0, 1}, {1, 2}, {2, 4}, {4, 8}, {8, 16}, {16, 32}, {32, 64}, {64, 128}, {128, 192}, {192, 200}}));
  // 256 pixels, a budget of 256 x 20: at most 16 samples a pass.
  EXPECT_EQ(passesOf(16, 16, 64, 256.0 * 20),
            (Passes{{0, 1}, {1, 2}, {2, 4}, {4, 8}, {8, 16}, {16, 32}, {32, 48}, {48, 64}}));
  Passes ones = passesOf(16, 16, 5, 100.0);
  EXPECT_EQ(ones, (Passes{{0, 1}, {1, 2}, {2, 3}, {3, 4}, {4, 5}}));
  for (double budget : {1.0, 300.0, 256.0 * 7, 256.0 * 64, 1e12}) {
    Passes p = passesOf(16, 16, 100, budget);
    ASSERT_FALSE(p.empty());
    EXPECT_EQ(p.front().first, 0);
    EXPECT_EQ(p.back().second, 100);
    for (size_t i = 0; i < p.size(); ++i) {
      int n = p[i].second - p[i].first;
      if (i + 1 < p.size()) {
        EXPECT_EQ(p[i].second, p[i + 1].first);
        EXPECT_EQ(n & (n - 1), 0) << "pass " << i << " of " << n << " samples";
        EXPECT_EQ(p[i].first % n, 0) << "pass " << i;
      }
      EXPECT_LE(double(n) * 256.0, std::max(budget, 256.0)) << "pass " << i;
    }
  }
}

// --spp 2147483647 (with a time limit, or until Ctrl-C) starts at once: the passes are made
// one at a time, where a list of all of them had overflowed int into a hang at 4 GB.
TEST(RenderPasses, TheLargestSampleCountStartsAtOnce) {
  RecordingExecutor ex(4, 4, 1e9);
  std::atomic<bool> cancel{false};
  ex.cancelAfter = &cancel;
  ex.cancelAfterPasses = 9;
  RenderOptions o;
  o.progress = false;
  o.cancel = &cancel;
  RenderStats st;
  renderPasses(ex, 4, 4, INT_MAX, o, &st);
  EXPECT_TRUE(st.cancelled);
  EXPECT_EQ(st.sppDone, 192);
  EXPECT_EQ(ex.passes, (Passes{{0, 1}, {1, 2}, {2, 4}, {4, 8}, {8, 16}, {16, 32}, {32, 64}, {64, 128}, {128, 192}}));
}

// A share of a render (RenderOptions::firstSample, sampleEnd) takes exactly its samples, in
// passes that start where it starts; a range outside the render, or a share of an adaptive
// render, is refused before any pass.
TEST(RenderPasses, AShareTakesOnlyItsSamples) {
  RecordingExecutor ex(4, 4, 1e9);
  RenderOptions o;
  o.progress = false;
  o.firstSample = 5, o.sampleEnd = 23;
  FilmSums film;
  o.filmOut = &film;
  RenderStats st;
  renderPasses(ex, 4, 4, 64, o, &st);
  EXPECT_EQ(ex.passes, (Passes{{5, 10}, {10, 20}, {20, 23}}));
  EXPECT_EQ(st.sppDone, 23);
  EXPECT_EQ(film.sum.size(), 16u);
  for (auto [first, end] : {std::pair{-1, 4}, std::pair{4, 4}, std::pair{0, 65}}) {
    RecordingExecutor bad(4, 4, 1e9);
    o.firstSample = first, o.sampleEnd = end;
    EXPECT_THROW(renderPasses(bad, 4, 4, 64, o, &st), std::runtime_error) << first << ":" << end;
    EXPECT_TRUE(bad.passes.empty());
  }
  o.firstSample = 8, o.sampleEnd = -1, o.noiseThreshold = 0.05f;
  RecordingExecutor adaptive(4, 4, 1e9);
  EXPECT_THROW(renderPasses(adaptive, 4, 4, 64, o, &st), std::runtime_error);
}

// The default budget leaves the bundled scenes' passes as they were (320 x 320: up to 64
// samples) and cuts a 4096 x 4096 image's to one sample.
TEST(RenderPasses, TheDefaultBudgetCutsOnlyLargeImages) {
  RecordingExecutor ex(1, 1, 0.0);
  const double budget = ex.PassExecutor::maxPassPixelSamples();
  EXPECT_GE(budget, 320.0 * 320.0 * 64.0);
  EXPECT_LT(budget, 4096.0 * 4096.0 * 2.0);
}

// A film too large for the machine is refused with its size, before any of it is allocated;
// where the system does not say how much memory it has, any film goes.
TEST(Film, AFilmThatCannotFitIsRefused) {
  Camera cam;
  cam.width = cam.height = 32768;
  RenderOptions o;
  EXPECT_EQ(filmBytesPerPixel(cam, o), 41u);  // two 12-byte sums, the mean image, 4 + 1 a pixel
  std::vector<float> var;
  o.varianceOut = &var;
  EXPECT_EQ(filmBytesPerPixel(cam, o), 57u);  // with each pixel's squared luminance, twice
  o.varianceOut = nullptr;
  o.noiseThreshold = 0.05f;
  EXPECT_EQ(filmBytesPerPixel(cam, o), 58u);  // adaptive: the variance, and the executor's mask once
  o.noiseThreshold = 0.f;
  o.aovChannels = 10;  // each channel and its copy in the written image, then that image's RGB
  EXPECT_EQ(filmBytesPerPixel(cam, o), 41u + 80u + 12u);
  cam.width = cam.height = 8192;  // 2.75 GB alone, 8.9 GB with the AOVs
  EXPECT_NO_THROW(requireFilmFits(cam, o, 100e9));
  try {
    requireFilmFits(cam, o, 16e9);
    ADD_FAILURE() << "an 8.9 GB film and AOVs were let through on a 16 GB machine";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("a 8192x8192 film with 10 AOV channels would take about 8.9 GB"),
              std::string::npos)
        << e.what();
    EXPECT_NE(std::string(e.what()).find("or fewer AOVs"), std::string::npos) << e.what();
  }
  cam.width = cam.height = 32768;
  o.aovChannels = 0;
  try {
    requireFilmFits(cam, o, 25.3e9);
    ADD_FAILURE() << "a 44 GB film was let through on a 25.3 GB machine";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("a 32768x32768 film would take about 44.0 GB, more than half of this "
                                         "machine's 25.3 GB"),
              std::string::npos)
        << e.what();
  }
  EXPECT_NO_THROW(requireFilmFits(cam, o, 0.0));
  EXPECT_NO_THROW(requireFilmFits(cam, o, 100e9));
  cam.width = cam.height = 8192;  // 2.75 GB
  EXPECT_NO_THROW(requireFilmFits(cam, o, 25.3e9));
}

// Ctrl-C in a pass that the executor cuts between tiles: the pixels that took it keep its
// samples, each pixel's mean is over its own count (so the image is 1 everywhere), and the
// first pass is never cut (it runs whole, then the render stops before the second).
TEST(RenderPasses, ACutPassKeepsTheSamplesOfThePixelsThatTookIt) {
  for (size_t cutAt : {1, 4}) {
    CuttingExecutor ex(8, cutAt, 3);
    std::atomic<bool> cancel{false};
    ex.raise = &cancel;
    RenderOptions o;
    o.progress = false;
    o.cancel = &cancel;
    std::vector<int> samples;
    o.samplesOut = &samples;
    RenderStats st;
    Image img = renderPasses(ex, 4, 2, 64, o, &st);
    EXPECT_TRUE(st.cancelled);
    for (float v : img.rgb) EXPECT_FLOAT_EQ(v, 1.f) << "cut at pass " << cutAt;
    if (cutAt == 1) {  // the first pass: whole, and no pixel ahead
      EXPECT_EQ(ex.passes, 1u);
      EXPECT_EQ(st.sppDone, 1);
      EXPECT_EQ(st.pixelsAhead, 0u);
      EXPECT_EQ(samples, std::vector<int>(8, 1));
    } else {  // passes 0-1, 1-2, 2-4 done; 4-8 cut after the first 3 pixels
      EXPECT_EQ(st.sppDone, 4);
      EXPECT_EQ(st.pixelsAhead, 3u);
      EXPECT_EQ(st.sppAhead, 8);
      EXPECT_EQ(samples, (std::vector<int>{8, 8, 8, 4, 4, 4, 4, 4}));
      EXPECT_EQ(st.pixelSamples, uint64_t(8 * 4 + 3 * 4));
    }
  }
}

// A checkpoint stops the passes while it is written, so checkpoints take at most about a tenth
// of the render: asked for after every pass (period 1 ms), with passes of 2 ms and a write of
// 40 ms, a render of 150 passes (about 0.3 s of passes) writes a handful, not 150.
TEST(RenderPasses, CheckpointsTakeAtMostATenthOfTheRender) {
  SlowExecutor ex(2);
  RenderOptions o;
  o.progress = false;
  o.checkpointSeconds = 0.001;
  int written = 0;
  o.checkpoint = [&](const Image&, int) {
    ++written;
    std::this_thread::sleep_for(std::chrono::milliseconds(40));
  };
  RenderStats st;
  renderPasses(ex, 2, 2, 151, o, &st);
  EXPECT_EQ(st.sppDone, 151);
  EXPECT_GE(written, 1);
  // Each write makes the next wait 0.4 s or more: at most a write a 0.4 s of the render.
  EXPECT_LE(written, 3) << "checkpoints every pass, each taking 20 times a pass";
}

// With a time limit, the pass after which the render stops gets no checkpoint: the final write
// follows at once with the same image (at 4096² a checkpoint is 3.5 s, written twice).
TEST(RenderPasses, NoCheckpointJustBeforeTheTimeLimitStops) {
  SlowExecutor ex(30);
  RenderOptions o;
  o.progress = false;
  o.checkpointSeconds = 0.001;
  o.timeLimitSeconds = 0.2;
  std::vector<int> written;
  o.checkpoint = [&](const Image&, int done) { written.push_back(done); };
  RenderStats st;
  renderPasses(ex, 2, 2, 1000, o, &st);
  EXPECT_TRUE(st.timeLimited);
  ASSERT_GE(st.sppDone, 2);
  ASSERT_FALSE(written.empty());
  EXPECT_LT(written.back(), st.sppDone) << "a checkpoint of the image the final write writes again";
}
