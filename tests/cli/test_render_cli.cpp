// `envgi render` end to end: outputs, determinism across thread counts, errors, and that an
// interrupted render still writes the samples it finished.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <csignal>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <thread>
#include <vector>

#include <fcntl.h>
#include <sys/wait.h>
#include <unistd.h>

#include "cli/CliRunner.h"
#include "core/PhysicalMemory.h"
#include "image/Image.h"
#include "support/SerializedFile.h"

using namespace envgi::test;
namespace fs = std::filesystem;

namespace {

std::string tinyScene(const TempDir& d, int res, int spp) {
  std::string path = d.file("tiny.xml");
  std::ofstream(path) << R"(<scene version="3.0.0">
  <default name="spp" value=")" << spp << R"("/>
  <integrator type="path"><integer name="max_depth" value="4"/></integrator>
  <sensor type="perspective"><float name="fov" value="45"/>
    <transform name="to_world"><lookat origin="0,1,4" target="0,0.5,0"/></transform>
    <film type="hdrfilm"><integer name="width" value=")" << res << R"("/><integer name="height" value=")" << res << R"("/></film>
    <sampler type="independent"><integer name="sample_count" value="$spp"/></sampler></sensor>
  <emitter type="envmap"><string name="filename" value=")" << ENVGI_SOURCE_DIR << R"(/scenes/envmaps/studio.hdr"/></emitter>
  <shape type="sphere"><point name="center" value="0,0.5,0"/><float name="radius" value="0.5"/>
    <bsdf type="roughconductor"><string name="material" value="Cu"/><float name="alpha" value="0.2"/></bsdf></shape>
  <shape type="rectangle"><transform name="to_world"><scale value="3"/><rotate x="1" angle="-90"/></transform></shape>
</scene>)";
  return path;
}

// `envgi render args` (split at spaces), its output to log; after 1.5 s, signal sig. Whether it
// ended within `seconds` of that, and (*status) its exit status (-1 if a signal ended it).
bool interruptedRender(const std::string& args, const std::string& log, double seconds, int* status = nullptr,
                       int sig = SIGINT) {
  std::vector<std::string> words = {ENVGI_CLI_PATH, "render"};
  std::istringstream in(args);
  for (std::string w; in >> w;) words.push_back(w);
  std::vector<char*> argv;
  for (std::string& w : words) argv.push_back(w.data());
  argv.push_back(nullptr);
  const pid_t pid = fork();
  if (pid < 0) return false;
  if (pid == 0) {
    const int fd = open(log.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    dup2(fd, 1);
    dup2(fd, 2);
    execv(argv[0], argv.data());
    _exit(127);
  }
  std::this_thread::sleep_for(std::chrono::milliseconds(1500));
  kill(pid, sig);
  int st = 0;
  for (int i = 0; i < int(seconds * 20); ++i) {
    if (waitpid(pid, &st, WNOHANG) == pid) {
      if (status) *status = WIFEXITED(st) ? WEXITSTATUS(st) : -1;
      return true;
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
  }
  kill(pid, SIGKILL);
  waitpid(pid, &st, 0);
  return false;
}

}  // namespace

TEST(CliRender, WritesExrAndPngAndReportsRate) {
  TempDir d;
  std::string scene = tinyScene(d, 24, 4);
  CliResult r = runCli("render " + scene + " -o " + d.file("a.exr") + " --png --no-progress");
  ASSERT_EQ(r.code, 0) << r.output;
  EXPECT_TRUE(fs::exists(d.file("a.exr")));
  EXPECT_TRUE(fs::exists(d.file("a.png")));
  EXPECT_NE(r.output.find("Mrays/s"), std::string::npos) << r.output;
  envgi::Image img = envgi::loadImage(d.file("a.exr"));
  EXPECT_EQ(img.width, 24);
  double mean = 0;
  for (float v : img.rgb) mean += v;
  EXPECT_GT(mean, 0.0);
}

TEST(CliRender, SameSeedSameImageWhateverTheThreadCount) {
  TempDir d;
  std::string scene = tinyScene(d, 20, 3);
  ASSERT_EQ(runCli("render " + scene + " -o " + d.file("t1.pfm") + " --threads 1 --seed 9 --no-progress").code, 0);
  ASSERT_EQ(runCli("render " + scene + " -o " + d.file("t2.pfm") + " --threads 2 --seed 9 --no-progress").code, 0);
  ASSERT_EQ(runCli("render " + scene + " -o " + d.file("t3.pfm") + " --threads 2 --seed 10 --no-progress").code, 0);
  EXPECT_EQ(slurp(d.file("t1.pfm")), slurp(d.file("t2.pfm")));
  EXPECT_NE(slurp(d.file("t1.pfm")), slurp(d.file("t3.pfm")));
}

TEST(CliRender, DefinesAndOverrides) {
  TempDir d;
  std::string scene = tinyScene(d, 8, 1);
  CliResult r = runCli("render " + scene + " -o " + d.file("o.exr") +
                       " -D spp=2 --integrator direct --strategy adaptive --no-progress");
  ASSERT_EQ(r.code, 0) << r.output;
  EXPECT_NE(r.output.find("'direct' (strategy adaptive), 2 spp"), std::string::npos) << r.output;
  EXPECT_EQ(r.output.find("has no parameter"), std::string::npos) << "spp is the scene's: " << r.output;
  // A -D name the scene never reads renders as without it, and says so with the nearest name.
  CliResult typo = runCli("render " + scene + " -o " + d.file("o.exr") + " -D sp=2 -D other=1 --no-progress");
  ASSERT_EQ(typo.code, 0) << typo.output;
  EXPECT_NE(typo.output.find("-D sp=2: " + scene + " has no parameter 'sp' (did you mean 'spp'?), so the value is not used"),
            std::string::npos)
      << typo.output;
  EXPECT_NE(typo.output.find("-D other=1: " + scene + " has no parameter 'other', so"), std::string::npos) << typo.output;
  EXPECT_NE(typo.output.find(", 1 spp"), std::string::npos) << typo.output;
}

TEST(CliRender, ErrorsLeaveNoOutput) {
  TempDir d;
  std::string out = d.file("never.exr");
  std::ofstream(d.file("broken.xml")) << "<scene version=\"3.0.0\">\n<shape type=\"sphere\">\n</scene>";
  CliResult r = runCli("render " + d.file("broken.xml") + " -o " + out);
  EXPECT_NE(r.code, 0);
  EXPECT_NE(r.output.find("envgi: error:"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("broken.xml:"), std::string::npos) << r.output;
  EXPECT_FALSE(fs::exists(out));
  std::string scene = tinyScene(d, 8, 1);
  EXPECT_NE(runCli("render " + scene + " -o " + d.file("x.txt")).code, 0);
  EXPECT_NE(runCli("render " + scene + " -o " + out + " --integrator bdpt").code, 0);
  EXPECT_NE(runCli("render " + scene + " -o " + out + " --strategy nonsense").code, 0);
  EXPECT_NE(runCli("render " + scene + " -o " + out + " -D broken").code, 0);
  EXPECT_FALSE(fs::exists(out));
  // The output's folders are made, as study makes its own (the README's `-o out/x.exr` on a
  // fresh checkout); one that cannot be made (a file in the way) is said before the render.
  CliResult newDir = runCli("render " + scene + " -o " + d.file("made/here/x.exr") + " --png --sample-map " +
                            d.file("maps/spp.png") + " --noise-threshold 0.5");
  EXPECT_EQ(newDir.code, 0) << newDir.output;
  EXPECT_TRUE(fs::exists(d.file("made/here/x.exr")));
  EXPECT_TRUE(fs::exists(d.file("made/here/x.png")));
  EXPECT_TRUE(fs::exists(d.file("maps/spp.png")));
  std::ofstream(d.file("afile")) << "x";
  CliResult noDir = runCli("render " + scene + " -o " + d.file("afile/x.exr"));
  EXPECT_EQ(noDir.code, 1) << noDir.output;
  EXPECT_NE(noDir.output.find("afile/x.exr': cannot make the folder"), std::string::npos) << noDir.output;
  EXPECT_EQ(noDir.output.find("100%"), std::string::npos) << noDir.output;
  CliResult noMapDir = runCli("render " + scene + " -o " + out + " --sample-map " + d.file("afile/spp.png"));
  EXPECT_NE(noMapDir.output.find("cannot make the folder"), std::string::npos) << noMapDir.output;
  EXPECT_FALSE(fs::exists(out));
  // A misspelt property (here the sphere's radius) is one error line naming the nearest name.
  std::string text;
  {
    std::ifstream in(scene);
    text.assign(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
  }
  text.replace(text.find("name=\"radius\""), 13, "name=\"raduis\"");
  std::ofstream(d.file("typo.xml")) << text;
  CliResult typo = runCli("render " + d.file("typo.xml") + " -o " + out);
  EXPECT_EQ(typo.code, 1) << typo.output;
  EXPECT_NE(typo.output.find("typo.xml:9: shape 'sphere' has no property 'raduis' (did you mean 'radius'?)"),
            std::string::npos)
      << typo.output;
  EXPECT_FALSE(fs::exists(out));
  size_t files = 0;
  for (auto& e : fs::directory_iterator(d.path)) files += e.path().filename().string().find(".tmp") != std::string::npos;
  EXPECT_EQ(files, 0u);
}

// A misspelt command or option gets the nearest name, as a misspelt XML property does.
TEST(CliRender, AMisspeltCommandOrOptionNamesTheNearest) {
  TempDir d;
  const std::string scene = tinyScene(d, 8, 1);
  CliResult command = runCli("rendr " + scene);
  EXPECT_EQ(command.code, 2) << command.output;
  EXPECT_NE(command.output.find("unknown command 'rendr' (did you mean 'render'?)"), std::string::npos)
      << command.output;
  CliResult option = runCli("render " + scene + " -o " + d.file("x.exr") + " --sp 4");
  EXPECT_EQ(option.code, 2) << option.output;
  EXPECT_NE(option.output.find("unknown option '--sp' (did you mean '--spp'?)"), std::string::npos) << option.output;
  EXPECT_FALSE(fs::exists(d.file("x.exr")));
  // Known options with values, -D pairs and negative numbers are not taken for misspellings.
  CliResult bad = runCli("render " + scene + " -o " + d.file("x.exr") + " -D spp=2 --seed -5");
  EXPECT_EQ(bad.output.find("unknown option"), std::string::npos) << bad.output;
}

// Options that change nothing on the scene are warned about: a strategy without a map, the
// collapsed map's size without a strategy that uses it.
TEST(CliRender, IgnoredOptionsAreSaid) {
  TempDir d;
  std::string text = slurp(tinyScene(d, 8, 1));
  const size_t at = text.find("<emitter"), end = text.find("</emitter>") + 10;
  text.replace(at, end - at, R"(<shape type="sphere"><point name="center" value="0,3,0"/><emitter type="area"><rgb name="radiance" value="5"/></emitter></shape>)");
  std::ofstream(d.file("lamp.xml")) << text;
  CliResult strategy = runCli("render " + d.file("lamp.xml") + " -o " + d.file("a.exr") + " --strategy importance");
  EXPECT_EQ(strategy.code, 0) << strategy.output;
  EXPECT_NE(strategy.output.find("--strategy importance: the scene has no environment map"), std::string::npos)
      << strategy.output;
  CliResult points = runCli("render " + tinyScene(d, 8, 1) + " -o " + d.file("b.exr") + " --points 8");
  EXPECT_EQ(points.code, 0) << points.output;
  EXPECT_NE(points.output.find("which strategy 'product' does not use"), std::string::npos) << points.output;
  CliResult used = runCli("render " + tinyScene(d, 8, 1) + " -o " + d.file("c.exr") + " --points 8 --strategy points "
                          "--integrator direct");
  EXPECT_EQ(used.code, 0) << used.output;
  EXPECT_EQ(used.output.find("does not use"), std::string::npos) << used.output;
}

// Participating media, which envgi does not render, are one warning wherever they appear: at
// the top level, nested in a shape, or referred to as a shape's interior (once "unexpected
// <medium> in <shape>" and "unknown BSDF id 'fog'").
TEST(CliRender, MediaAreAWarningWhereverTheyAppear) {
  TempDir d;
  std::string text = slurp(tinyScene(d, 8, 1));
  text.replace(text.find("<shape type=\"sphere\">"), 22,
               R"(<medium type="homogeneous" id="fog"/>
  <shape type="sphere"><ref name="interior" id="fog"/>
    <medium type="homogeneous" name="exterior"/>)");
  std::ofstream(d.file("fog.xml")) << text;
  CliResult r = runCli("render " + d.file("fog.xml") + " -o " + d.file("fog.exr"));
  EXPECT_EQ(r.code, 0) << r.output;
  size_t warnings = 0;
  for (size_t at = r.output.find("participating media are not supported"); at != std::string::npos;
       at = r.output.find("participating media are not supported", at + 1))
    ++warnings;
  EXPECT_EQ(warnings, 3u) << r.output;
  EXPECT_TRUE(fs::exists(d.file("fog.exr")));
}

// A scene whose only emitter envgi does not support (sunsky, sky, projector) has no light: the
// render is an error naming that, where it drew a black image and exited 0 after a warning.
TEST(CliRender, ASceneWithoutLightIsAnError) {
  TempDir d;
  std::string text = slurp(tinyScene(d, 8, 1));
  const size_t at = text.find("<emitter"), end = text.find("</emitter>") + 10;
  text.replace(at, end - at, R"(<emitter type="sunsky"/>)");
  std::ofstream(d.file("sunsky.xml")) << text;
  CliResult r = runCli("render " + d.file("sunsky.xml") + " -o " + d.file("black.exr"));
  EXPECT_EQ(r.code, 1) << r.output;
  EXPECT_NE(r.output.find("emitter type 'sunsky' is not supported"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("envgi: error: the scene emits no light"), std::string::npos) << r.output;
  EXPECT_FALSE(fs::exists(d.file("black.exr")));
  // Its AOVs alone need no light.
  CliResult aovs = runCli("render " + d.file("sunsky.xml") + " -o " + d.file("aovs.exr") + " --aov dd:depth");
  EXPECT_EQ(aovs.code, 0) << aovs.output;
}

// SIGINT or SIGTERM during a long render: the finished passes are written, and the exit status
// is the shell's for the signal (130, 143), so a script can tell a stopped render from a
// finished one (both exited 0).
TEST(CliRender, InterruptKeepsFinishedWork) {
  for (int sig : {SIGINT, SIGTERM}) {
    TempDir d;
    std::string scene = tinyScene(d, 64, 100000);
    std::string out = d.file("long.exr");
    int status = -2;
    ASSERT_TRUE(interruptedRender(scene + " -o " + out + " --no-progress", d.file("log.txt"), 10.0, &status, sig));
    std::string log = slurp(d.file("log.txt"));
    EXPECT_EQ(status, 128 + sig) << log;
    EXPECT_TRUE(fs::exists(out)) << log;
    EXPECT_NE(log.find("interrupted: wrote the"), std::string::npos) << log;
  }
}

// SIGINT while the grid integrator still gathers into its first grid (1.8 M points, 128 rays
// each: minutes on two cores): the render ends within seconds with one error line and no
// image, where it had run on until the first pass. A grid that could never fit in memory is
// refused before anything is allocated.
TEST(CliRender, InterruptWhilePreparingEndsWithoutAnImage) {
  TempDir d;
  std::string scene = tinyScene(d, 16, 1);
  std::string text = slurp(scene);
  text.replace(text.find("<integrator"), text.find("</integrator>") + 13 - text.find("<integrator"),
               R"(<integrator type="grid"><integer name="resolution" value="120"/></integrator>)");
  std::ofstream(scene) << text;
  std::string out = d.file("grid.exr");
  bool gone = interruptedRender(scene + " -o " + out + " --no-progress", d.file("log.txt"), 20.0);
  std::string log = slurp(d.file("log.txt"));
  EXPECT_TRUE(gone) << "still running 20 s after SIGINT\n" << log;
  EXPECT_NE(log.find("interrupted before the first pass finished: no image written"), std::string::npos) << log;
  EXPECT_FALSE(fs::exists(out));

  // The same over a cube 2 a side (the floor gone): 513^3 points.
  text.replace(text.find("value=\"120\""), 11, "value=\"512\"");
  size_t floor = text.find("<shape type=\"rectangle\"");
  ASSERT_NE(floor, std::string::npos);
  text.replace(floor, text.find("</shape>", floor) + 8 - floor, R"(<shape type="cube"/>)");
  std::ofstream(scene) << text;
  if (envgi::physicalMemoryBytes() >= 29e9) {  // 513^3 points take 14.6 GB: it would fit, and run for hours
    std::printf("this machine holds a 14.6 GB grid: its refusal is left to the unit test\n");
    return;
  }
  CliResult huge = runCli("render " + scene + " -o " + out + " --no-progress");
  {
    EXPECT_EQ(huge.code, 1) << huge.output;
    EXPECT_NE(huge.output.find("points would take 14.6 GB, more than half of this machine's"), std::string::npos)
        << huge.output;
    EXPECT_FALSE(fs::exists(out));
  }
}

// A film larger than half the machine's memory is refused before it is allocated: a 32768^2
// film (44 GB) had thrashed a 25 GB machine for minutes. With the path and photon integrators
// (the photon pass comes after the check).
TEST(CliRender, AFilmTooLargeForTheMachineIsRefused) {
  if (envgi::physicalMemoryBytes() >= 88.2e9) {  // 44.0 GB would fit
    std::printf("this machine holds a 32768^2 film: its refusal is left to the unit test\n");
    return;
  }
  TempDir d;
  std::string scene = tinyScene(d, 32768, 1);
  for (const char* integrator : {"path", "photon"}) {
    std::string out = d.file(std::string(integrator) + ".exr");
    auto t0 = std::chrono::steady_clock::now();
    CliResult r = runCli("render " + scene + " --integrator " + integrator + " -o " + out + " --no-progress");
    double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    EXPECT_EQ(r.code, 1) << r.output;
    EXPECT_NE(r.output.find("a 32768x32768 film would take about 44.0 GB, more than half of this machine's"),
              std::string::npos)
        << r.output;
    EXPECT_FALSE(fs::exists(out));
    EXPECT_LT(seconds, 30.0) << integrator;
  }
}

// An allocation the system refuses (here the 8192^2 film's sums, 805 MB, past a 600 MB
// address-space limit) ends with one line naming it, exit 1 and no image, where it used to
// print "std::bad_alloc". Not under AddressSanitizer, whose shadow memory alone passes the
// limit, nor on a machine under 6 GB, where envgi's own film bound refuses it first.
TEST(CliRender, AnAllocationTheSystemRefusesIsOneErrorLine) {
#if defined(__SANITIZE_ADDRESS__)
  GTEST_SKIP() << "AddressSanitizer reserves more address space than the limit this test sets";
#endif
  if (envgi::physicalMemoryBytes() < 6e9) GTEST_SKIP() << "an 8192^2 film is refused by envgi's own bound here";
  TempDir d;
  std::string out = d.file("big.exr");
  CliResult r = runCli("render " + std::string(ENVGI_SOURCE_DIR) + "/scenes/cornell-box.xml -D res=8192 --spp 1 " +
                           "--integrator path --no-progress -o " + out,
                       "ulimit -v 600000; ");
  EXPECT_EQ(r.code, 1) << r.output;
  EXPECT_NE(r.output.find("envgi: error: out of memory: the system refused an allocation"), std::string::npos)
      << r.output;
  EXPECT_FALSE(fs::exists(out));
}

// A time limit ends a render of far more samples than fit at a pass boundary, with the image
// of the samples done and a log line saying how many.
TEST(CliRender, TimeLimitStopsAtAPassWithTheSamplesDone) {
  TempDir d;
  std::string scene = tinyScene(d, 32, 1000000);
  std::string out = d.file("limited.exr");
  auto t0 = std::chrono::steady_clock::now();
  CliResult r = runCli("render " + scene + " -o " + out + " --no-progress --time-limit 0.5");
  double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  ASSERT_EQ(r.code, 0) << r.output;
  EXPECT_LT(seconds, 60.0);  // a million samples of 32x32 would take minutes
  EXPECT_NE(r.output.find("time limit of 0.5 s: stopped after"), std::string::npos) << r.output;
  envgi::Image img = envgi::loadImage(out);
  EXPECT_EQ(img.width, 32);
  double sum = 0.0;
  for (float v : img.rgb) sum += v;
  EXPECT_GT(sum, 0.0);
  CliResult bad = runCli("render " + scene + " -o " + d.file("x.exr") + " --time-limit -1");
  EXPECT_NE(bad.code, 0) << bad.output;
  EXPECT_FALSE(fs::exists(d.file("x.exr")));
}

// Adaptive sampling from the command line: the log says how many samples it took, and the
// sample map shows the background stopping at --min-spp while the sphere and floor go on.
TEST(CliRender, NoiseThresholdStopsConvergedPixelsAndMapsTheirSamples) {
  TempDir d;
  std::string scene = tinyScene(d, 32, 64);
  std::string out = d.file("adaptive.exr"), map = d.file("samples.pfm");
  CliResult r = runCli("render " + scene + " -o " + out + " --no-progress --noise-threshold 0.05 --min-spp 8 --sample-map " + map);
  ASSERT_EQ(r.code, 0) << r.output;
  EXPECT_NE(r.output.find("adaptive: noise threshold 0.05 from 8 spp"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("adaptive sampling: "), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("of the pixels stopped early"), std::string::npos) << r.output;
  envgi::Image m = envgi::loadImage(map);
  ASSERT_EQ(m.width, 32);
  int atMin = 0, atAll = 0;
  for (size_t i = 0; i < m.rgb.size(); i += 3) {
    float share = m.rgb[i];
    EXPECT_TRUE(share == 0.125f || share == 0.25f || share == 0.5f || share == 1.f) << share;
    atMin += share == 0.125f;
    atAll += share == 1.f;
  }
  EXPECT_GT(atMin, 0) << "the map's background converges at once";
  EXPECT_GT(atAll, 0) << "the glossy sphere does not";
  EXPECT_TRUE(fs::exists(out));
  // With the progress log on, the bar counts the samples taken and still ends at 100%.
  CliResult withBar = runCli("render " + scene + " -o " + out + " --noise-threshold 0.05 --min-spp 8");
  ASSERT_EQ(withBar.code, 0) << withBar.output;
  std::istringstream lines(withBar.output);
  std::string line, lastBar;
  while (std::getline(lines, line))
    if (line.find("elapsed") != std::string::npos) lastBar = line;
  EXPECT_NE(lastBar.find("] 100%"), std::string::npos) << withBar.output;
  // Bad values stop before anything is written.
  for (const std::string& bad : std::vector<std::string>{"--noise-threshold -1", "--noise-threshold nan", "--min-spp 1",
                          "--noise-threshold 0.1 --sample-map " + d.file("m.txt"),
                          "--noise-threshold 0.1 --integrator sppm"}) {
    std::string o = d.file("bad.exr");
    CliResult b = runCli("render " + scene + " -o " + o + " --no-progress " + bad);
    EXPECT_NE(b.code, 0) << bad << "\n" << b.output;
    EXPECT_FALSE(fs::exists(o)) << bad;
  }
}

// Under a time limit the progress log (every 10% when not on a terminal) counts the time too:
// no line promises more time left than the limit, and the bar gets past half way (by samples
// alone it would stay near 0%).
TEST(CliRender, TimeLimitProgressFollowsTheClock) {
  TempDir d;
  std::string scene = tinyScene(d, 32, 1000000);
  CliResult r = runCli("render " + scene + " -o " + d.file("p.exr") + " --time-limit 1");
  ASSERT_EQ(r.code, 0) << r.output;
  std::istringstream lines(r.output);
  std::string line;
  int bars = 0, lastPct = -1;
  while (std::getline(lines, line)) {
    size_t left = line.find("s left");
    if (line.empty() || line[0] != '[' || left == std::string::npos) continue;
    ++bars;
    size_t comma = line.rfind(", ", left);
    ASSERT_NE(comma, std::string::npos) << line;
    EXPECT_LE(std::stod(line.substr(comma + 2, left - comma - 2)), 1.0) << line;
    lastPct = std::stoi(line.substr(line.find(']') + 1));
  }
  EXPECT_GE(bars, 2) << r.output;
  EXPECT_GE(lastPct, 50) << r.output;
}

TEST(CliPhotons, DrawsPhotonsAndRejectsBadInput) {
  TempDir d;
  std::string scene = std::string(ENVGI_SOURCE_DIR) + "/scenes/cornell-box.xml";
  CliResult r = runCli("photons " + scene + " -o " + d.file("p.png") + " -D res=64 --global 2000 --caustic 2000");
  ASSERT_EQ(r.code, 0) << r.output;
  EXPECT_NE(r.output.find("global photons orange, caustic photons cyan"), std::string::npos) << r.output;
  EXPECT_GT(fs::file_size(d.file("p.png")), 500u);
  EXPECT_NE(r.output.find("caustic photons"), std::string::npos) << r.output;
  CliResult bad = runCli("photons " + scene + " -o " + d.file("p.txt"));
  EXPECT_NE(bad.code, 0);
  EXPECT_FALSE(fs::exists(d.file("p.txt")));
  CliResult missing = runCli("photons /nonexistent.xml -o " + d.file("q.png"));
  EXPECT_NE(missing.code, 0);
  EXPECT_FALSE(fs::exists(d.file("q.png")));
}

// Delta lights are reached by emitter samples only: BSDF samples alone leave them out, and the
// log says so.
TEST(CliRender, DeltaLightsWithoutEmitterSamplesAreReported) {
  TempDir d;
  std::string scene = std::string(ENVGI_SOURCE_DIR) + "/scenes/sun-and-sky.xml";
  CliResult r = runCli("render " + scene + " -o " + d.file("s.exr") + " --integrator direct --strategy bsdf --spp 1 "
                       "-D res=16 --no-progress");
  ASSERT_EQ(r.code, 0) << r.output;
  EXPECT_NE(r.output.find("the 2 directional, point or spot light(s) add nothing"), std::string::npos) << r.output;
  CliResult path = runCli("render " + scene + " -o " + d.file("p.exr") + " --spp 1 -D res=16 --no-progress");
  ASSERT_EQ(path.code, 0) << path.output;
  EXPECT_NE(path.output.find("2 directional/point/spot lights"), std::string::npos) << path.output;
  EXPECT_EQ(path.output.find("add nothing"), std::string::npos) << path.output;
}

// The bundled probe scene: an angular map read through the envmap's layout, and the log says so.
TEST(CliRender, AngularProbeSceneRenders) {
  TempDir d;
  std::string scene = std::string(ENVGI_SOURCE_DIR) + "/scenes/uffizi-probe.xml", out = d.file("u.exr");
  CliResult r = runCli("render " + scene + " -o " + out + " --spp 2 -D res=16 --no-progress");
  ASSERT_EQ(r.code, 0) << r.output;
  EXPECT_NE(r.output.find("(angular map, 128x128) resampled to a 256x128 lat-long map"), std::string::npos) << r.output;
  CliResult c = runCli("compare " + out + " " + out);
  ASSERT_EQ(c.code, 0) << c.output;
  EXPECT_EQ(c.output.find("nan"), std::string::npos) << c.output;
}

TEST(CliRender, PhotonSppmAndGridIntegrators) {
  TempDir d;
  // The Cornell box with a small grid in its file (resolution 8, 16 gather rays): --integrator
  // keeps the settings the file gives the same type, and the default grid took 5 s of the 15.
  std::ifstream in(std::string(ENVGI_SOURCE_DIR) + "/scenes/cornell-box.xml");
  std::stringstream xml;
  xml << in.rdbuf();
  std::string text = xml.str();
  size_t from = text.find("<integrator"), to = text.find("</integrator>");
  ASSERT_TRUE(from != std::string::npos && to != std::string::npos);
  text.replace(from, to + 13 - from,
               R"(<integrator type="grid"><integer name="resolution" value="8"/><integer name="gather_rays" value="16"/>
               <integer name="global_photons" value="20000"/><integer name="caustic_photons" value="5000"/></integrator>)");
  std::string scene = d.file("cornell-box.xml");
  std::ofstream(scene) << text;
  for (std::string integ : {"photon", "sppm", "grid"}) {
    CliResult r = runCli("render " + scene + " -o " + d.file("c.exr") + " --integrator " + integ +
                         " --spp 2 -D res=24 --no-progress");
    ASSERT_EQ(r.code, 0) << r.output;
    EXPECT_NE(r.output.find(integ == "sppm" ? "sppm: 2 passes" : integ == "grid" ? "16 gather rays each" : "photon pass:"),
              std::string::npos)
        << r.output;
  }
  std::ofstream(d.file("grid.xml")) << R"(<scene version="3.0.0"><integrator type="grid"><integer name="resolution" value="1"/></integrator></scene>)";
  CliResult badGrid = runCli("render " + d.file("grid.xml") + " -o " + d.file("x.exr"));
  EXPECT_NE(badGrid.code, 0);
  EXPECT_NE(badGrid.output.find("resolution must be between 2 and 512"), std::string::npos) << badGrid.output;
  // Two billion photons (over 300 GB of maps) are one error line, not a process the kernel kills.
  std::ofstream(d.file("huge.xml")) << text.substr(0, text.find("<integrator")) +
                                           R"(<integrator type="photon"><integer name="global_photons" value="2000000000"/></integrator>)" +
                                           text.substr(text.find("</integrator>") + 13);
  CliResult huge = runCli("render " + d.file("huge.xml") + " -o " + d.file("huge.exr") + " --spp 1 -D res=8 --no-progress");
  EXPECT_EQ(huge.code, 1) << huge.output;
  EXPECT_NE(huge.output.find("photon maps of 2000250000 photons would take about"), std::string::npos) << huge.output;
  // It names the settings of both commands that set the counts.
  EXPECT_NE(huge.output.find("global_photons and caustic_photons, or --global and --caustic"), std::string::npos)
      << huge.output;
  EXPECT_FALSE(fs::exists(d.file("huge.exr")));
  std::ofstream(d.file("bad.xml")) << R"(<scene version="3.0.0"><integrator type="sppm"><float name="alpha" value="1.5"/></integrator></scene>)";
  CliResult bad = runCli("render " + d.file("bad.xml") + " -o " + d.file("x.exr"));
  EXPECT_NE(bad.code, 0);
  EXPECT_NE(bad.output.find("alpha must be in (0, 1)"), std::string::npos) << bad.output;
}

// max_depth -1 in a photon integrator's own element (Mitsuba's "unbounded") lights the Cornell
// box as the default depth does; it had ended every photon and camera chain at once (black).
TEST(CliRender, PhotonIntegratorsReadMaxDepthMinusOneAsUnbounded) {
  TempDir d;
  std::ifstream in(std::string(ENVGI_SOURCE_DIR) + "/scenes/cornell-box.xml");
  std::stringstream xml;
  xml << in.rdbuf();
  const std::string text = xml.str();
  size_t from = text.find("<integrator"), to = text.find("</integrator>");
  ASSERT_TRUE(from != std::string::npos && to != std::string::npos);
  double mean[2] = {0.0, 0.0};
  for (int k = 0; k < 2; ++k) {
    std::string t = text;
    t.replace(from, to + 13 - from,
              std::string(R"(<integrator type="photon"><integer name="global_photons" value="20000"/>)") +
                  R"(<integer name="caustic_photons" value="5000"/><integer name="gather_samples" value="2"/>)" +
                  (k == 0 ? R"(<integer name="max_depth" value="-1"/>)" : "") + "</integrator>");
    std::string scene = d.file("cornell-" + std::to_string(k) + ".xml");
    std::ofstream(scene) << t;
    CliResult r = runCli("render " + scene + " -o " + d.file("c.pfm") + " --spp 2 -D res=24 --no-progress --seed 3");
    ASSERT_EQ(r.code, 0) << r.output;
    envgi::Image img = envgi::loadImage(d.file("c.pfm"));
    for (int y = 0; y < img.height; ++y)
      for (int x = 0; x < img.width; ++x) mean[k] += img.at(x, y).y / double(img.width * img.height);
  }
  std::printf("image mean: max_depth -1 %.4f, default %.4f\n", mean[0], mean[1]);
  EXPECT_NEAR(mean[0], mean[1], 0.05 * mean[1]);
  EXPECT_GT(mean[1], 0.1);
}

// A textured diffuse square filling the view under a constant sky of radiance 1 reflects its
// albedo, so each quarter of the image shows its texel. The rectangle's
// v runs up the square and texture rows down the image (as in Mitsuba): texel row 0 is the
// image's bottom half.
TEST(CliRender, TexturedAlbedoFromTheCommandLine) {
  TempDir d;
  envgi::Image tex(2, 2);
  const envgi::Color texels[2][2] = {{{0.2f, 0.4f, 0.6f}, {0.8f, 0.1f, 0.3f}}, {{0.05f, 0.5f, 0.9f}, {0.7f, 0.7f, 0.1f}}};
  for (int y = 0; y < 2; ++y)
    for (int x = 0; x < 2; ++x) tex.set(x, y, texels[y][x]);
  envgi::saveImage(tex, d.file("tex.exr"));
  std::ofstream(d.file("tex.xml")) << R"(<scene version="3.0.0">
  <integrator type="path"><integer name="max_depth" value="3"/></integrator>
  <sensor type="perspective"><float name="fov" value="43.6028"/>
    <transform name="to_world"><lookat origin="0,0,2.5" target="0,0,0" up="0,1,0"/></transform>
    <film type="hdrfilm"><integer name="width" value="32"/><integer name="height" value="32"/></film>
    <sampler type="independent"><integer name="sample_count" value="16"/></sampler></sensor>
  <emitter type="constant"><rgb name="radiance" value="1"/></emitter>
  <shape type="rectangle"><bsdf type="diffuse"><texture type="bitmap" name="reflectance">
    <string name="filename" value="tex.exr"/><string name="filter_type" value="nearest"/></texture></bsdf></shape>
</scene>)";
  // Every integrator's textured bounces: Furnace.TexturedEnclosureGivesItsAnalyticRadiance.
  for (std::string integ : {"path", "direct", "photon"}) {
    CliResult r = runCli("render " + d.file("tex.xml") + " -o " + d.file("t.exr") + " --integrator " + integ +
                         " --seed 5 --no-progress");
    ASSERT_EQ(r.code, 0) << r.output;
    envgi::Image img = envgi::loadImage(d.file("t.exr"));
    for (int qy = 0; qy < 2; ++qy)
      for (int qx = 0; qx < 2; ++qx) {
        // The middle of each quarter: photon estimates blur the square's outer edges.
        double sum[3] = {0, 0, 0};
        int n = 0;
        for (int y = qy * 16 + 4; y < qy * 16 + 12; ++y)
          for (int x = qx * 16 + 4; x < qx * 16 + 12; ++x, ++n)
            for (int c = 0; c < 3; ++c) sum[c] += img.rgb[(size_t(y) * 32 + x) * 3 + c];
        const envgi::Color want = texels[1 - qy][qx];
        const float wantC[3] = {want.x, want.y, want.z};
        for (int c = 0; c < 3; ++c)
          EXPECT_NEAR(sum[c] / n, wantC[c], 0.04 * wantC[c] + 0.01)
              << integ << ", quarter (" << qx << ", " << qy << "), channel " << c;
      }
  }
}

// A thin lens seen through its analytic blur: a black-and-white step (a checkerboard edge on
// a plane parallel to the lens, at depth D, under a constant sky of radiance 1) with the lens
// focused at F. The rays of one film position then meet the plane on a uniform disk of radius
// R = A |D - F| / F about the pinhole ray's hit, so a pixel shows the part of that disk on the
// white side: g(-X / R), with g(s) = (acos s - s sqrt(1 - s^2)) / pi, X the pixel's offset
// from the edge on the plane. A pinhole would show a sharp step.
TEST(CliRender, ThinLensBlursAStepByItsCircleOfConfusion) {
  TempDir d;
  const double A = 0.25, D = 10.0, F = 5.0, R = A * std::fabs(D - F) / F;  // 8 pixels
  std::ofstream(d.file("lens.xml")) << R"(<scene version="3.0.0">
  <integrator type="path"><integer name="max_depth" value="2"/></integrator>
  <sensor type="thinlens"><float name="fov" value="11.421186"/>
    <float name="aperture_radius" value="0.25"/><float name="focus_distance" value="5"/>
    <transform name="to_world"><lookat origin="0,0,0" target="0,0,-1" up="0,1,0"/></transform>
    <film type="hdrfilm"><integer name="width" value="64"/><integer name="height" value="4"/><rfilter type="box"/></film>
    <sampler type="independent"><integer name="sample_count" value="256"/></sampler></sensor>
  <emitter type="constant"><rgb name="radiance" value="1"/></emitter>
  <shape type="rectangle"><transform name="to_world"><scale value="20"/><translate z="-10"/></transform>
    <bsdf type="diffuse"><texture type="checkerboard" name="reflectance">
      <rgb name="color0" value="1"/><rgb name="color1" value="0"/>
      <transform name="to_uv"><translate y="0.25"/></transform></texture></bsdf></shape>
</scene>)";
  auto g = [](double s) {
    s = std::clamp(s, -1.0, 1.0);
    return (std::acos(s) - s * std::sqrt(1.0 - s * s)) / M_PI;
  };
  for (std::string integ : {"path", "direct"}) {
    CliResult r = runCli("render " + d.file("lens.xml") + " -o " + d.file("l.exr") + " --integrator " + integ +
                         " --seed 3 --no-progress");
    ASSERT_EQ(r.code, 0) << r.output;
    envgi::Image img = envgi::loadImage(d.file("l.exr"));
    ASSERT_EQ(img.width, 64);
    for (int x = 0; x < 64; ++x) {
      double got = 0.0;
      for (int y = 0; y < 4; ++y) got += img.at(x, y).y / 4.0;
      // The plane spans [-1, 1] across the image (tan(fov / 2) D = 1); the white half is +x,
      // the image's right. The box filter averages over the pixel.
      double want = 0.0;
      for (int k = 0; k < 32; ++k) want += g(-(-1.0 + (x + (k + 0.5) / 32.0) / 32.0) / R) / 32.0;
      EXPECT_NEAR(got, want, 0.06) << integ << ", column " << x;  // 1024 samples: sigma <= 0.016
    }
  }
}

// --samples S0:S1 renders a share of the render: two halves average to the whole render to
// float rounding (the tiny scene's filter has no negative lobes), and a range that is not one,
// lies past --spp, or asks it of an integrator that renders whole is one error line, no file.
TEST(RenderCli, SampleRangesSplitARender) {
  TempDir d;
  std::string scene = tinyScene(d, 16, 8);
  auto render = [&](const std::string& name, const std::string& extra) {
    return runCli("render " + scene + " -o " + d.file(name) + " --spp 8 --no-progress " + extra);
  };
  ASSERT_EQ(render("whole.exr", "").code, 0);
  ASSERT_EQ(render("a.exr", "--samples 0:3").code, 0);
  ASSERT_EQ(render("b.exr", "--samples 3:8").code, 0);
  const envgi::Image whole = envgi::loadImage(d.file("whole.exr")), a = envgi::loadImage(d.file("a.exr")),
                     b = envgi::loadImage(d.file("b.exr"));
  double diff = 0.0, mean = 0.0, apart = 0.0;
  for (size_t i = 0; i < whole.rgb.size(); ++i) {
    diff = std::max(diff, std::fabs(double(whole.rgb[i]) - (3.0 * a.rgb[i] + 5.0 * b.rgb[i]) / 8.0));
    mean += whole.rgb[i];
    apart += std::fabs(double(a.rgb[i]) - b.rgb[i]);
  }
  EXPECT_LT(diff, 1e-5 * (1.0 + mean / double(whole.rgb.size())));
  EXPECT_GT(apart, 0.0) << "the two shares took different samples";
  for (auto [extra, message] : {std::pair<std::string, std::string>{"--samples 5", "give S0:S1"},
                                {"--samples 6:2", "give S0:S1"},
                                {"--samples 0:x", "give S0:S1"},
                                {"--samples 4:16", "not a range within the render's 8"},
                                {"--samples 0:4 --time-limit 5", "takes all of its samples"},
                                {"--samples 0:4 --integrator sppm", "renders as a whole"}}) {
    CliResult r = render("bad.exr", extra);
    EXPECT_EQ(r.code, 1) << extra << "\n" << r.output;
    EXPECT_NE(r.output.find(message), std::string::npos) << extra << "\n" << r.output;
    EXPECT_FALSE(fs::exists(d.file("bad.exr"))) << extra;
  }
}

// --device: auto falls back to the CPU without a GPU, and says so; cuda without one is one
// error line and no output file; a bad device name is an error.
TEST(RenderCli, DeviceChoice) {
  TempDir d;
  std::string scene = tinyScene(d, 16, 2);
  bool gpu = runCli("render " + scene + " -o " + d.file("probe.exr") + " --device cuda --no-progress").code == 0;
  CliResult a = runCli("render " + scene + " -o " + d.file("auto.exr") + " --device auto --no-progress");
  ASSERT_EQ(a.code, 0) << a.output;
  EXPECT_TRUE(fs::exists(d.file("auto.exr")));
  CliResult c = runCli("render " + scene + " -o " + d.file("cuda.exr") + " --device cuda --no-progress");
  if (!gpu) {
    EXPECT_NE(a.output.find("device: CPU"), std::string::npos) << a.output;
    EXPECT_EQ(c.code, 1);
    EXPECT_NE(c.output.find("envgi: error: --device cuda: no CUDA device"), std::string::npos) << c.output;
    EXPECT_FALSE(fs::exists(d.file("cuda.exr")));
  } else {
    EXPECT_EQ(c.code, 0) << c.output;
  }
  CliResult bad = runCli("render " + scene + " -o " + d.file("bad.exr") + " --device tpu");
  EXPECT_EQ(bad.code, 1);
  EXPECT_NE(bad.output.find("unknown device 'tpu'"), std::string::npos) << bad.output;
  // Every integrator has a GPU part (photon: its photon maps), so with a GPU each renders with
  // --device cuda; without one each is the same one error line.
  for (std::string integ : {"sppm", "photon", "grid"}) {
    CliResult r = runCli("render " + scene + " -o " + d.file(integ + ".exr") + " --device cuda --integrator " + integ +
                         " --spp 1 --no-progress");
    if (gpu) {
      EXPECT_EQ(r.code, 0) << r.output;
    } else {
      EXPECT_EQ(r.code, 1) << r.output;
      EXPECT_NE(r.output.find("envgi: error: --device cuda: no CUDA device"), std::string::npos) << r.output;
      EXPECT_FALSE(fs::exists(d.file(integ + ".exr")));
    }
  }
}

// --gpus: a list's form is checked first, then the devices present; with one GPU or more the
// render splits over them (render/SplitRender.h, tested on the CPU), and with none it is one
// error line and no file.
TEST(RenderCli, GpusListsAreChecked) {
  TempDir d;
  std::string scene = tinyScene(d, 16, 2);
  const std::string out = " -o " + d.file("gpus.exr") + " --no-progress ";
  auto expectError = [&](const std::string& args, const std::string& message) {
    CliResult r = runCli("render " + scene + out + args);
    EXPECT_TRUE(r.code == 1 || r.code == 2) << args << ": " << r.code << " " << r.output;
    EXPECT_NE(r.output.find(message), std::string::npos) << args << ": " << r.output;
    EXPECT_FALSE(fs::exists(d.file("gpus.exr"))) << args;
  };
  expectError("--gpus 0,x", "--gpus 0,x: give all, or device numbers separated by commas (0,1,2)");
  expectError("--gpus 0,,1", "give all, or device numbers");
  expectError("--gpus -1", "give all, or device numbers");
  expectError("--gpus 1,0,1", "--gpus 1,0,1: names GPU 1 twice");
  expectError("--gpus all --device cpu", "--gpus: the render is on the CPU (--device cpu)");
  expectError("--gpus 0,1 --gpu 1", "--gpu excludes --gpus");
  bool gpu = runCli("render " + scene + " -o " + d.file("probe.exr") + " --device cuda --no-progress").code == 0;
  if (!gpu) {
    expectError("--gpus all", "envgi: error: --gpus: no CUDA device");
    expectError("--gpus 0,1 --integrator sppm", "envgi: error: --gpus: no CUDA device");
  } else {
    expectError("--gpus 4096", "--gpus 4096: there is no GPU 4096");
  }
}

// The log flags work before or after the subcommand: -q leaves warnings and errors only (no
// progress bar either), -v is accepted there too.
TEST(RenderCli, LogFlagsBeforeOrAfterTheSubcommand) {
  TempDir d;
  std::string scene = tinyScene(d, 8, 1);
  for (std::string args : {"-q render " + scene + " -o " + d.file("a.exr") + " --no-progress",
                           "render " + scene + " -o " + d.file("b.exr") + " --no-progress -q"}) {
    CliResult r = runCli(args);
    EXPECT_EQ(r.code, 0) << args << ": " << r.output;
    EXPECT_EQ(r.output.find("[info]"), std::string::npos) << args << ": " << r.output;
  }
  // -q without --no-progress: nothing at all on a clean render, the progress bar included.
  CliResult quiet = runCli("-q render " + scene + " -o " + d.file("q.exr"));
  EXPECT_EQ(quiet.code, 0) << quiet.output;
  EXPECT_EQ(quiet.output, "");
  CliResult loud = runCli("render " + scene + " -o " + d.file("c.exr") + " --no-progress --verbose");
  EXPECT_EQ(loud.code, 0) << loud.output;
  EXPECT_NE(loud.output.find("[info]"), std::string::npos) << loud.output;
  // An option no command knows is still one error line, exit 2.
  CliResult bad = runCli("render " + scene + " -o " + d.file("d.exr") + " --bogus");
  EXPECT_EQ(bad.code, 2) << bad.output;
  EXPECT_FALSE(fs::exists(d.file("d.exr")));
}

// --sampler on render, --version, and parse errors as one `envgi: error:` line.
TEST(RenderCli, SamplerVersionAndParseErrors) {
  TempDir d;
  std::string scene = tinyScene(d, 8, 2);
  CliResult s = runCli("render " + scene + " -o " + d.file("s.exr") + " --sampler stratified --no-progress");
  EXPECT_EQ(s.code, 0) << s.output;
  EXPECT_NE(s.output.find("stratified sampler"), std::string::npos) << s.output;
  EXPECT_EQ(runCli("render " + scene + " -o " + d.file("t.exr") + " --sampler halton").code, 1);
  EXPECT_EQ(runCli("render " + scene + " -o " + d.file("f.exr") + " --filter tent --no-progress").code, 0);
  CliResult l = runCli("render " + scene + " -o " + d.file("l.exr") + " --filter lanczos --no-progress");
  EXPECT_EQ(l.code, 0) << l.output;
  EXPECT_NE(l.output.find("independent sampler, lanczos filter"), std::string::npos) << l.output;
  CliResult f = runCli("render " + scene + " -o " + d.file("g.exr") + " --filter lanczoz");
  EXPECT_NE(f.output.find("unknown filter 'lanczoz' (box, tent, gaussian, mitchell, catmullrom, lanczos)"),
            std::string::npos)
      << f.output;
  EXPECT_FALSE(fs::exists(d.file("g.exr")));
  // The collapsed map's options and the device index: bad values are one error line, no file.
  for (std::string bad : {"--strategy points --point-method bogus", "--strategy magic", "--points 0", "--gpu -1"}) {
    CliResult b = runCli("render " + scene + " -o " + d.file("bad.exr") + " --no-progress " + bad);
    EXPECT_NE(b.code, 0) << bad;
    // One error line (the scene's own loader warning may come before it).
    size_t at = b.output.find("envgi: error: ");
    ASSERT_NE(at, std::string::npos) << bad << ": " << b.output;
    EXPECT_EQ(b.output.find("envgi: error: ", at + 1), std::string::npos) << bad << ": " << b.output;
    EXPECT_EQ(b.output.find('\n', at), b.output.size() - 1) << bad << ": " << b.output;
    EXPECT_FALSE(fs::exists(d.file("bad.exr"))) << bad;
  }
  CliResult pts = runCli("render " + scene + " -o " + d.file("p.exr") + " --no-progress --strategy points-draw --points 8 "
                         "--point-method mediancut");
  EXPECT_EQ(pts.code, 0) << pts.output;
  CliResult all = runCli("render " + scene + " -o " + d.file("a.exr") + " --no-progress --integrator direct --strategy points "
                         "--points 8 --point-method mediancut");
  EXPECT_EQ(all.code, 0) << all.output;
  CliResult v = runCli("--version");
  EXPECT_EQ(v.code, 0);
  EXPECT_EQ(v.output.rfind("envgi ", 0), 0u) << v.output;
  CliResult missing = runCli("render " + d.file("nope.xml") + " -o " + d.file("x.exr"));
  EXPECT_EQ(missing.code, 2);
  EXPECT_EQ(missing.output.rfind("envgi: error: ", 0), 0u) << missing.output;
  EXPECT_EQ(std::count(missing.output.begin(), missing.output.end(), '\n'), 1) << missing.output;
}

// A camera at 3e38 makes rays outside Embree's range (1.844e18), on which Debian's Embree
// asserts and aborts: every integrator must render it (those rays miss) and exit 0.
TEST(CliRender, RaysOutsideEmbreesRangeMissInsteadOfAborting) {
  TempDir d;
  std::ofstream(d.file("far.xml")) << R"(<scene version="3.0.0">
  <sensor type="perspective"><transform name="to_world"><translate x="3e38"/></transform>
    <film type="hdrfilm"><integer name="width" value="8"/><integer name="height" value="8"/></film></sensor>
  <emitter type="constant"/>
  <shape type="sphere"/>
</scene>)";
  for (std::string integrator : {"path", "direct", "photon", "sppm", "grid"}) {
    CliResult r = runCli("render " + d.file("far.xml") + " --integrator " + integrator + " --spp 2 --no-progress -o " +
                         d.file(integrator + ".exr"));
    EXPECT_EQ(r.code, 0) << integrator << ": " << r.output;
    EXPECT_TRUE(fs::exists(d.file(integrator + ".exr"))) << integrator;
  }
}

// Numeric options out of range, or NaN, are one sentence naming the option and the value, exit
// 2, and no file; they used to pass (NaN time limit and exposure, negative photon counts and
// checkpoint periods, ten million threads) or quote a range up to 1.8e308.
TEST(RenderCli, NumericOptionsOutOfRangeAreOneClearError) {
  TempDir d;
  std::string scene = tinyScene(d, 8, 2);
  struct Case {
    std::string args, expect;
  };
  std::string render = "render " + scene + " -o " + d.file("bad.png") + " --no-progress ";
  std::vector<Case> cases = {
      {render + "--spp 0", "--spp: must be at least 1, not 0"},
      {render + "--time-limit nan", "--time-limit: 'nan' is not a number"},
      {render + "--checkpoint -1", "--checkpoint: must be at least 0, not -1"},
      {render + "--exposure inf", "--exposure: 'inf' is not a finite number"},
      {render + "--threads -2", "--threads: must be from 0 to 1024, not -2"},
      // oneTBB's arena crashed (SIGSEGV) when asked for ten million threads.
      {render + "--threads 10000000", "--threads: must be from 0 to 1024, not 10000000"},
      {render + "--threads 2.5", "--threads: '2.5' is not a whole number"},
      {render + "--points 2000000000", "--points: must be from 1 to 16777216, not 2000000000"},
      // The seed is 32 bits (a larger one was cut short); a misspelt point method was ignored.
      {render + "--seed 99999999999", "--seed: must be from 0 to 4294967295, not 99999999999"},
      {render + "--strategy points --point-method median", "--point-method: median not in {sample,mediancut}"},
      {"view " + scene + " --threads 1025", "--threads: must be from 0 to 1024, not 1025"},
      // Two billion map samples had ended in std::bad_alloc.
      {"envmap samples " + std::string(ENVGI_SOURCE_DIR) + "/scenes/envmaps/studio.hdr -n 2000000000 -o " +
           d.file("bad.png"),
       "--count: must be from 1 to 16777216, not 2000000000"},
      {"photons " + scene + " -o " + d.file("bad.png") + " --global -5", "--global: must be at least 0, not -5"},
      {"study " + scene + " -o " + d.file("study") + " --reference-spp 0", "--reference-spp: must be at least 1, not 0"},
      {"study " + scene + " -o " + d.file("study") + " --threads -1",
       "--threads: must be from 0 to 1024, not -1"},
  };
  for (const Case& c : cases) {
    CliResult r = runCli(c.args);
    EXPECT_EQ(r.code, 2) << c.args << ": " << r.output;
    EXPECT_EQ(r.output.rfind("envgi: error: " + c.expect, 0), 0u) << c.args << ": " << r.output;
  }
  EXPECT_FALSE(fs::exists(d.file("bad.png")));
  EXPECT_FALSE(fs::exists(d.file("study")));
}

// --sample-map is written after the image: named as the image, or as the PNG beside it, it
// would have replaced it. Refused before the render.
TEST(RenderCli, ASampleMapCannotOverwriteTheImage) {
  TempDir d;
  std::string scene = tinyScene(d, 8, 2);
  for (const std::string& extra : {" -o " + d.file("a.exr") + " --sample-map " + d.file("a.exr"),
                                   " -o " + d.file("b.exr") + " --png --sample-map " + d.file("b.png")}) {
    CliResult r = runCli("render " + scene + extra + " --no-progress");
    EXPECT_EQ(r.code, 1) << extra << ": " << r.output;
    EXPECT_NE(r.output.find("would overwrite the rendered image"), std::string::npos) << r.output;
  }
  EXPECT_FALSE(fs::exists(d.file("a.exr")));
  EXPECT_FALSE(fs::exists(d.file("b.exr")));
  CliResult ok = runCli("render " + scene + " -o " + d.file("c.exr") + " --png --sample-map " + d.file("c-samples.png") +
                        " --no-progress");
  EXPECT_EQ(ok.code, 0) << ok.output;
  EXPECT_TRUE(fs::exists(d.file("c.png")) && fs::exists(d.file("c-samples.png")));
}

// An output (or the PNG beside it, or a sample map) that names a folder is refused before the
// render: the rename onto it failed only once every sample had been taken.
TEST(RenderCli, AnOutputThatIsAFolderIsRefusedBeforeTheRender) {
  TempDir d;
  std::string scene = tinyScene(d, 8, 2);
  fs::create_directories(d.file("a.exr") + "/x");
  fs::create_directories(d.file("b.png") + "/x");
  fs::create_directories(d.file("m.png") + "/x");
  for (const std::string& extra : {" -o " + d.file("a.exr"), " -o " + d.file("b.exr") + " --png",
                                   " -o " + d.file("c.exr") + " --sample-map " + d.file("m.png")}) {
    CliResult r = runCli("render " + scene + extra + " --no-progress");
    EXPECT_EQ(r.code, 1) << extra << ": " << r.output;
    EXPECT_NE(r.output.find("it is a folder"), std::string::npos) << r.output;
    EXPECT_EQ(r.output.find("rendering "), std::string::npos) << "refused before the render: " << r.output;
  }
}

// An output that stops being writable during the render (its folder gone, a full disk; here a
// folder made where the image was): each checkpoint after that is a warning and the render goes
// on; at the end its samples go to the temporary folder, named in the one error line (exit 1).
TEST(RenderCli, AnOutputThatStopsBeingWritableLosesNoSamples) {
  TempDir d;
  std::string scene = tinyScene(d, 32, 100000);
  // Renders for `seconds` with `env` before the command; once the first checkpoint is written,
  // makes folders where the image and the sample map go. Returns the log, ending "rc=N".
  auto breakMidRender = [&](const std::string& env, const std::string& name, double seconds) {
    const std::string out = d.file(name + ".exr"), map = d.file(name + "-spp.exr"), log = d.file(name + ".log");
    std::string cmd = "sh -c '" + env + " " + std::string(ENVGI_CLI_PATH) + " render " + scene + " -o " + out +
                      " --sample-map " + map + " --no-progress --checkpoint 0.2 --time-limit " +
                      std::to_string(seconds) + "; echo rc=$?' > " + log + " 2>&1 &";
    EXPECT_EQ(std::system(cmd.c_str()), 0);
    for (int i = 0; i < 200 && !fs::exists(out); ++i) std::this_thread::sleep_for(std::chrono::milliseconds(50));
    EXPECT_TRUE(fs::exists(out)) << "no first checkpoint in 10 s\n" << slurp(log);
    fs::remove(out);
    fs::create_directories(out + "/x");
    fs::create_directories(map + "/x");  // the sample map, written only at the end
    for (int i = 0; i < 600 && slurp(log).find("rc=") == std::string::npos; ++i)
      std::this_thread::sleep_for(std::chrono::milliseconds(50));
    return slurp(log);
  };
  const std::string text = breakMidRender("", "img", 3.0), out = d.file("img.exr");
  ASSERT_NE(text.find("rc=1"), std::string::npos) << text;
  EXPECT_NE(text.find("not written (cannot write '" + out + "': it is a folder); rendering on"), std::string::npos)
      << text;
  // Both files, each under its own name: "were written to 'A' and 'B' instead".
  const std::string said = "were written to '";
  size_t at = text.find(said);
  ASSERT_NE(at, std::string::npos) << text;
  at += said.size();
  const std::string rescue = text.substr(at, text.find('\'', at) - at);
  at = text.find(" and '", at);
  ASSERT_NE(at, std::string::npos) << text;
  at += 6;
  const std::string rescuedMap = text.substr(at, text.find('\'', at) - at);
  EXPECT_NE(rescue.find("img.exr"), std::string::npos) << rescue;
  EXPECT_NE(rescuedMap.find("img-spp.exr"), std::string::npos) << rescuedMap;
  envgi::Image img = envgi::loadImage(rescue), spp = envgi::loadImage(rescuedMap);
  fs::remove(rescue);
  fs::remove(rescuedMap);
  EXPECT_EQ(img.width, 32);
  double sum = 0.0;
  for (float v : img.rgb) sum += v;
  EXPECT_GT(sum, 0.0);
  EXPECT_EQ(spp.width, 32);
  EXPECT_GT(spp.rgb[0], 0.f) << "every pixel took samples";

  // With no temporary folder either, the error is still the output's, and claims no rescue.
  const std::string none = breakMidRender("TMPDIR=" + d.file("absent"), "none", 1.5);
  ASSERT_NE(none.find("rc=1"), std::string::npos) << none;
  EXPECT_NE(none.find("envgi: error: cannot write '" + d.file("none.exr") + "': it is a folder\n"), std::string::npos)
      << none;
  EXPECT_EQ(none.find("were written to"), std::string::npos) << none;
}

// compare: an image against itself has no error, a noisier one has some, a wrong size is one
// error line and no table.
TEST(CliCompare, ErrorsAgainstAReference) {
  TempDir d;
  std::string scene = std::string(ENVGI_SOURCE_DIR) + "/scenes/cornell-box.xml";
  ASSERT_EQ(runCli("render " + scene + " -o " + d.file("a.pfm") + " --spp 8 -D res=16 --no-progress").code, 0);
  ASSERT_EQ(runCli("render " + scene + " -o " + d.file("b.pfm") + " --spp 1 -D res=16 --no-progress").code, 0);
  ASSERT_EQ(runCli("render " + scene + " -o " + d.file("c.pfm") + " --spp 1 -D res=8 --no-progress").code, 0);
  CliResult r = runCli("compare " + d.file("a.pfm") + " " + d.file("a.pfm") + " " + d.file("b.pfm"));
  ASSERT_EQ(r.code, 0) << r.output;
  std::istringstream lines(r.output);
  std::string line, name;
  std::vector<double> rmse;
  while (std::getline(lines, line)) {
    std::istringstream ls(line);
    double mean, e;
    if (ls >> name >> mean >> e && name.find(".pfm") != std::string::npos) rmse.push_back(e);
  }
  ASSERT_EQ(rmse.size(), 2u) << r.output;
  EXPECT_EQ(rmse[0], 0.0);
  EXPECT_NE(r.output.find("worst-region: the largest RMSE of a 4 x 4 grid of regions"), std::string::npos) << r.output;
  EXPECT_GT(rmse[1], 0.0);
  CliResult bad = runCli("compare " + d.file("a.pfm") + " " + d.file("c.pfm"));
  EXPECT_NE(bad.code, 0);
  EXPECT_NE(bad.output.find("reference is 16x16, the image 8x8"), std::string::npos) << bad.output;
  EXPECT_EQ(bad.output.find("RMSE"), std::string::npos) << "no half table: " << bad.output;

  // NaN: counted in the last column, and every error of that image NaN (the worst region was
  // 0); a reference with one is an error.
  envgi::Image nan = envgi::loadImage(d.file("b.pfm"));
  nan.rgb[40] = NAN;
  envgi::saveImage(nan, d.file("nan.pfm"));
  CliResult withNan = runCli("compare " + d.file("a.pfm") + " " + d.file("nan.pfm"));
  ASSERT_EQ(withNan.code, 0) << withNan.output;
  std::string row = withNan.output.substr(withNan.output.find("nan.pfm"));
  std::istringstream fields(row);
  std::string path, meanText, rmseText, rel, worst, count;
  fields >> path >> meanText >> rmseText >> rel >> worst >> count;
  EXPECT_EQ(worst, "nan") << withNan.output;
  EXPECT_EQ(count, "1") << withNan.output;
  CliResult nanRef = runCli("compare " + d.file("nan.pfm") + " " + d.file("a.pfm"));
  EXPECT_EQ(nanRef.code, 1);
  EXPECT_NE(nanRef.output.find("has 1 NaN or infinite values"), std::string::npos) << nanRef.output;

  // An 8-bit image on either side is refused before any table: its values are display codes.
  envgi::saveImage(envgi::loadImage(d.file("a.pfm")), d.file("a.png"));
  for (std::string args : {d.file("a.pfm") + " " + d.file("a.png"), d.file("a.png") + " " + d.file("a.pfm"),
                           d.file("a.pfm") + " " + d.file("b.pfm") + " " + d.file("a.png")}) {
    CliResult ldr = runCli("compare " + args);
    EXPECT_EQ(ldr.code, 1) << args;
    EXPECT_NE(ldr.output.find("is not a radiance image"), std::string::npos) << ldr.output;
    EXPECT_EQ(ldr.output.find("RMSE"), std::string::npos) << "no table: " << ldr.output;
  }
}

// Mitsuba's film flag sample_border is what envgi always does (each pixel's samples come from its
// filter), so a scene that sets it renders with no warning about it.
TEST(CliRender, FilmSampleBorderIsAccepted) {
  TempDir d;
  std::string scene = tinyScene(d, 8, 1);
  std::string text = slurp(scene);
  text.replace(text.find("<film type=\"hdrfilm\">"), std::string("<film type=\"hdrfilm\">").size(),
               "<film type=\"hdrfilm\"><boolean name=\"sample_border\" value=\"true\"/>");
  std::ofstream(scene) << text;
  CliResult r = runCli("render " + scene + " -o " + d.file("out.exr") + " --no-progress");
  EXPECT_EQ(r.code, 0) << r.output;
  EXPECT_EQ(r.output.find("sample_border"), std::string::npos) << r.output;
}

// The bundled normal-map scene, end to end with path and sppm: its domes darken the image by a
// third against the same scene with a flat normal map (rgb (0.5, 0.5, 1): the frame as it is,
// given by -D normalmap), measured 0.061 against 0.094 at 32 spp; two seeds of one scene agree
// within 0.2%.
TEST(CliRender, NormalMapSceneRenders) {
  TempDir d;
  const std::string scene = std::string(ENVGI_SOURCE_DIR) + "/scenes/normal-map.xml";
  envgi::Image flat(4, 4);
  for (size_t i = 0; i < flat.rgb.size(); i += 3) {
    flat.rgb[i] = flat.rgb[i + 1] = 0.5f;
    flat.rgb[i + 2] = 1.f;
  }
  envgi::saveImage(flat, d.file("flat-normals.exr"));
  const std::pair<std::string, std::string> maps[] = {{"domes", ""}, {"flat", " -D normalmap=" + d.file("flat-normals.exr")}};
  for (std::string integ : {"path", "sppm"}) {
    double mean[2] = {0.0, 0.0};
    int k = 0;
    for (const auto& [name, define] : maps) {
      CliResult r = runCli("render " + scene + define + " -o " + d.file(name + ".exr") + " --integrator " + integ +
                           " --spp 8 -D res=32 --no-progress");
      ASSERT_EQ(r.code, 0) << r.output;
      EXPECT_EQ(r.output.find("warn"), std::string::npos) << r.output;
      envgi::Image img = envgi::loadImage(d.file(name + ".exr"));
      for (float v : img.rgb) {
        ASSERT_TRUE(std::isfinite(v)) << integ << " " << name;
        mean[k] += v;
      }
      mean[k++] /= double(img.rgb.size());
    }
    EXPECT_LT(mean[0], 0.8 * mean[1]) << integ << ": the domes should darken the image";
    EXPECT_GT(mean[0], 0.4 * mean[1]) << integ;
  }
  // A map that is not there: one error line naming the scene, exit 1, no image.
  CliResult missing = runCli("render " + scene + " -D normalmap=" + d.file("nothing.png") + " -o " + d.file("m.exr"));
  EXPECT_EQ(missing.code, 1) << missing.output;
  EXPECT_NE(missing.output.find("envgi: error: "), std::string::npos) << missing.output;
  EXPECT_NE(missing.output.find("normal-map.xml:"), std::string::npos) << missing.output;
  EXPECT_FALSE(fs::exists(d.file("m.exr")));
}

// The bundled mask scene, end to end with path and sppm: no warning, a finite image, and a
// canopy made solid (-D lattice=1) darkens the floor and sphere below it against one whose open
// squares are empty (-D lattice=0; 8% brighter there at 64 spp); path and sppm agree on each.
TEST(CliRender, MaskSceneRenders) {
  TempDir d;
  const std::string scene = std::string(ENVGI_SOURCE_DIR) + "/scenes/mask.xml";
  double mean[2][2] = {};
  const char* integrators[] = {"path", "sppm"};
  for (int i = 0; i < 2; ++i)
    for (int open = 0; open < 2; ++open) {
      std::string out = d.file(std::string(integrators[i]) + std::to_string(open) + ".exr");
      CliResult r = runCli("render " + scene + " -o " + out + " --integrator " + integrators[i] + " -D lattice=" +
                           (open ? "0" : "1") + " --spp 16 -D res=32 --no-progress");
      ASSERT_EQ(r.code, 0) << r.output;
      EXPECT_EQ(r.output.find("warn"), std::string::npos) << r.output;
      envgi::Image img = envgi::loadImage(out);
      for (float v : img.rgb) ASSERT_TRUE(std::isfinite(v)) << integrators[i];
      // The middle half of the rows: the canopy's shadow on the floor and the white sphere.
      for (int y = img.height / 4; y < 3 * img.height / 4; ++y)
        for (int x = 0; x < img.width; ++x) mean[i][open] += img.at(x, y).y / (0.5 * img.height * img.width);
    }
  for (int i = 0; i < 2; ++i) EXPECT_GT(mean[i][1], 1.05 * mean[i][0]) << integrators[i] << ": open squares let the sun through";
  for (int open = 0; open < 2; ++open) EXPECT_NEAR(mean[1][open], mean[0][open], 0.1 * mean[0][open]) << "lattice " << 1 - open;
}

// A crop window renders its part of the film: a textured sphere under a sky of 1 (each pixel
// its texture's albedo, nearly free of noise), rendered whole at 48 x 32 and as the 20 x 12
// window at (22, 9); the window's pixels are the whole image's there, within 0.01 on average.
TEST(CliRender, ACropWindowRendersItsPartOfTheFilm) {
  TempDir d;
  auto scene = [&](const std::string& name, const std::string& crop) {
    std::string xml = d.file(name + ".xml");
    std::ofstream(xml) << R"(<scene version="3.0.0"><integrator type="path"><integer name="max_depth" value="2"/></integrator>
  <sensor type="perspective"><float name="fov" value="40"/>
    <transform name="to_world"><lookat origin="0,0,4" target="0,0,0" up="0,1,0"/></transform>
    <film type="hdrfilm"><integer name="width" value="48"/><integer name="height" value="32"/>)" + crop + R"(
      <rfilter type="box"/></film></sensor>
  <emitter type="constant"><rgb name="radiance" value="1"/></emitter>
  <shape type="sphere"><bsdf type="diffuse"><texture type="bitmap" name="reflectance">
    <string name="filename" value=")" + std::string(ENVGI_SOURCE_DIR) + R"(/scenes/textures/uv-grid.png"/></texture></bsdf></shape>
</scene>)";
    std::string out = d.file(name + ".exr");
    CliResult r = runCli("render " + xml + " -o " + out + " --spp 64 --no-progress");
    EXPECT_EQ(r.code, 0) << r.output;
    return envgi::loadImage(out);
  };
  envgi::Image whole = scene("whole", "");
  envgi::Image window = scene("window", R"(<integer name="crop_offset_x" value="22"/><integer name="crop_offset_y" value="9"/>
      <integer name="crop_width" value="20"/><integer name="crop_height" value="12"/>)");
  ASSERT_EQ(window.width, 20);
  ASSERT_EQ(window.height, 12);
  double diff = 0.0, mean = 0.0;
  for (int y = 0; y < 12; ++y)
    for (int x = 0; x < 20; ++x) {
      diff += std::fabs(window.at(x, y).y - whole.at(x + 22, y + 9).y) / 240.0;
      mean += window.at(x, y).y / 240.0;
    }
  EXPECT_LT(diff, 0.01);
  EXPECT_GT(mean, 0.1) << "the window sees the sphere";
}

// A bundled scene end to end with path and sppm (32^2, 16 spp): no warning, a finite image that
// is not black, and the two integrators agree on its mean within 10%.
namespace {
void expectPathAndSppmAgree(const std::string& name) {
  TempDir d;
  const std::string scene = std::string(ENVGI_SOURCE_DIR) + "/scenes/" + name + ".xml";
  double mean[2] = {};
  const char* integrators[] = {"path", "sppm"};
  for (int i = 0; i < 2; ++i) {
    std::string out = d.file(std::string(integrators[i]) + ".exr");
    CliResult r = runCli("render " + scene + " -o " + out + " --integrator " + integrators[i] +
                         " --spp 16 -D res=32 --no-progress");
    ASSERT_EQ(r.code, 0) << r.output;
    EXPECT_EQ(r.output.find("warn"), std::string::npos) << r.output;
    envgi::Image img = envgi::loadImage(out);
    ASSERT_EQ(img.width, 32);
    for (float v : img.rgb) ASSERT_TRUE(std::isfinite(v)) << integrators[i];
    for (int y = 0; y < img.height; ++y)
      for (int x = 0; x < img.width; ++x) mean[i] += img.at(x, y).y / (img.height * img.width);
    EXPECT_GT(mean[i], 0.05) << integrators[i];
  }
  EXPECT_NEAR(mean[1], mean[0], 0.1 * mean[0]) << name;
}
}  // namespace

TEST(CliRender, OrthographicSceneRenders) { expectPathAndSppmAgree("orthographic"); }
TEST(CliRender, InstancesSceneRenders) { expectPathAndSppmAgree("instances"); }
TEST(CliRender, TexturedLightSceneRenders) { expectPathAndSppmAgree("textured-light"); }

// A scene written with a shapegroup and instances renders the same to the bit as the same
// shapes written out one by one with the instances' to_world (path, 32^2, 8 spp).
TEST(CliRender, InstancesRenderAsTheShapesTheyPlace) {
  TempDir d;
  const std::string head = std::string(R"(<scene version="3.0.0">
  <integrator type="path"><integer name="max_depth" value="4"/></integrator>
  <sensor type="perspective"><float name="fov" value="45"/>
    <transform name="to_world"><lookat origin="0,1.5,5" target="0,0.4,0"/></transform>
    <film type="hdrfilm"><integer name="width" value="32"/><integer name="height" value="32"/></film>
    <sampler type="sobol"><integer name="sample_count" value="8"/></sampler></sensor>
  <emitter type="envmap"><string name="filename" value=")") + ENVGI_SOURCE_DIR + R"(/scenes/envmaps/studio.hdr"/></emitter>
  <shape type="rectangle"><transform name="to_world"><scale value="3"/><rotate x="1" angle="-90"/></transform></shape>
)";
  const char* placements[] = {R"(<translate x="-1"/>)", R"(<rotate y="1" angle="30"/><scale value="0.5"/><translate x="1" y="0.2"/>)"};
  const std::string sphere = R"(<float name="radius" value="0.4"/>
    <bsdf type="roughconductor"><string name="material" value="Cu"/><float name="alpha" value="0.2"/></bsdf>)";
  const std::string cube = R"(<bsdf type="diffuse"><rgb name="reflectance" value="0.2,0.5,0.7"/></bsdf>)";
  std::string grouped = head + "<shape type=\"shapegroup\" id=\"g\"><shape type=\"sphere\">" + sphere +
                        "</shape><shape type=\"cube\">" + cube + "</shape></shape>\n";
  std::string plain = head;
  for (const char* t : placements) {
    const std::string xf = std::string("<transform name=\"to_world\">") + t + "</transform>";
    grouped += "<shape type=\"instance\"><ref id=\"g\"/>" + xf + "</shape>\n";
    plain += "<shape type=\"sphere\">" + sphere + xf + "</shape><shape type=\"cube\">" + cube + xf + "</shape>\n";
  }
  std::ofstream(d.file("grouped.xml")) << grouped << "</scene>\n";
  std::ofstream(d.file("plain.xml")) << plain << "</scene>\n";
  for (const char* name : {"grouped", "plain"}) {
    CliResult r = runCli(std::string("render ") + d.file(std::string(name) + ".xml") + " -o " +
                         d.file(std::string(name) + ".exr") + " --threads 1 --no-progress");
    ASSERT_EQ(r.code, 0) << name << ": " << r.output;
    if (std::string(name) == "grouped") {
      EXPECT_NE(r.output.find("2 instances placed 4 shapes; their meshes share 1 shapegroup meshes (12 triangles stored for 24 placed)"),
                std::string::npos)
          << r.output;
    }
  }
  // The sphere is a copy either way; the cube is placed by Embree's instancing in one and
  // written out in the other, so its hit points differ in their last bits: the same image up to
  // float rounding, and the odd pixel where a ray grazes an edge.
  envgi::Image a = envgi::loadImage(d.file("grouped.exr")), b = envgi::loadImage(d.file("plain.exr"));
  ASSERT_EQ(a.rgb.size(), b.rgb.size());
  double mean = 0.0, meanB = 0.0;
  size_t close = 0;
  for (size_t i = 0; i < a.rgb.size(); ++i) {
    mean += a.rgb[i] / double(a.rgb.size());
    meanB += b.rgb[i] / double(b.rgb.size());
    close += std::fabs(a.rgb[i] - b.rgb[i]) <= 1e-3f * (1.f + std::fabs(b.rgb[i]));
  }
  EXPECT_GT(mean, 0.05);
  EXPECT_GE(double(close), 0.99 * double(a.rgb.size())) << "the instanced scene differs from the plain one";
  EXPECT_NEAR(mean, meanB, 1e-3 * meanB);
}
TEST(CliRender, BlendSceneRenders) { expectPathAndSppmAgree("blend"); }

// The bundled principled scene, end to end with path, sppm and direct: no warning (every
// property is read), a finite image that is not black; path and sppm, both consistent, agree on
// its mean. (photon and grid take 8-10 s here for their maps; test_Principled.cpp checks what
// they read of the BSDF.)
TEST(CliRender, PrincipledSceneRenders) {
  TempDir d;
  const std::string scene = std::string(ENVGI_SOURCE_DIR) + "/scenes/principled.xml";
  double means[2] = {0.0, 0.0};
  int k = 0;
  for (std::string integ : {"path", "sppm", "direct"}) {
    CliResult r = runCli("render " + scene + " -o " + d.file(integ + ".exr") + " --integrator " + integ +
                         " --spp 16 -D res=32 --seed 3 --no-progress");
    ASSERT_EQ(r.code, 0) << integ << ": " << r.output;
    EXPECT_EQ(r.output.find("warn"), std::string::npos) << integ << ": " << r.output;
    envgi::Image img = envgi::loadImage(d.file(integ + ".exr"));
    double mean = 0.0;
    for (float v : img.rgb) {
      ASSERT_TRUE(std::isfinite(v)) << integ;
      mean += v;
    }
    mean /= double(img.rgb.size());
    EXPECT_GT(mean, 0.02) << integ;
    if (k < 2) means[k++] = mean;
  }
  EXPECT_NEAR(means[0], means[1], 0.1 * means[0]) << "path against sppm";
}

// Mitsuba's volpath (a scene without media) renders as path, to the bit, and the log says so.
TEST(CliRender, VolpathRendersAsPath) {
  TempDir d;
  std::string text = slurp(tinyScene(d, 16, 4));
  const std::string from = "<integrator type=\"path\">";
  ASSERT_NE(text.find(from), std::string::npos);
  std::ofstream(d.file("volpath.xml")) << std::string(text).replace(text.find(from), from.size(), "<integrator type=\"volpath\">");
  std::ofstream(d.file("path.xml")) << text;
  for (const char* name : {"volpath", "path"}) {
    CliResult r = runCli(std::string("render ") + d.file(std::string(name) + ".xml") + " -o " +
                         d.file(std::string(name) + ".exr") + " --seed 5 --no-progress");
    ASSERT_EQ(r.code, 0) << name << ": " << r.output;
    EXPECT_EQ(r.output.find("warn"), std::string::npos) << r.output;
    EXPECT_EQ(r.output.find("integrator 'volpath' is read as 'path'") != std::string::npos,
              std::string(name) == "volpath")
        << r.output;
  }
  EXPECT_TRUE(envgi::loadImage(d.file("volpath.exr")).rgb == envgi::loadImage(d.file("path.exr")).rgb);
}

// --aov writes the AOVs as channels of the .exr (the image's RGB the same to the bit as without
// them), and the log names them; a scene's aov integrator does the same; AOVs into a .png are an
// error before any sample.
TEST(CliRender, AovsAreChannelsOfTheExr) {
  TempDir d;
  const std::string scene = tinyScene(d, 16, 4);
  CliResult plain = runCli("render " + scene + " -o " + d.file("plain.exr") + " --threads 1 --no-progress");
  ASSERT_EQ(plain.code, 0) << plain.output;
  CliResult r = runCli("render " + scene + " -o " + d.file("aov.exr") +
                       " --threads 1 --no-progress --aov 'alb:albedo,dd:depth,nn:sh_normal'");
  ASSERT_EQ(r.code, 0) << r.output;
  EXPECT_NE(r.output.find("AOVs alb.R, alb.G, alb.B, dd.T, nn.X, nn.Y, nn.Z from 4 camera samples"), std::string::npos)
      << r.output;
  envgi::Image img = envgi::loadImage(d.file("aov.exr"));
  EXPECT_TRUE(img.rgb == envgi::loadImage(d.file("plain.exr")).rgb);
  ASSERT_EQ(img.channels.size(), 7u);
  const envgi::ImageChannel* depth = nullptr;
  for (const envgi::ImageChannel& c : img.channels)
    if (c.name == "dd.T") depth = &c;
  ASSERT_NE(depth, nullptr);
  // The bottom row sees the floor, the top row the sky (depth 0).
  EXPECT_GT(depth->values[15 * 16 + 8], 1.f);
  EXPECT_EQ(depth->values[8], 0.f);

  // The same from the scene file's aov integrator around its path integrator.
  std::string text = slurp(scene);
  const std::string from = "<integrator type=\"path\"><integer name=\"max_depth\" value=\"4\"/></integrator>";
  ASSERT_NE(text.find(from), std::string::npos);
  text.replace(text.find(from), from.size(),
               "<integrator type=\"aov\"><string name=\"aovs\" value=\"alb:albedo,dd:depth,nn:sh_normal\"/>" + from +
                   "</integrator>");
  std::ofstream(d.file("aov.xml")) << text;
  CliResult s = runCli("render " + d.file("aov.xml") + " -o " + d.file("scene.exr") + " --threads 1 --no-progress");
  ASSERT_EQ(s.code, 0) << s.output;
  envgi::Image fromScene = envgi::loadImage(d.file("scene.exr"));
  EXPECT_TRUE(fromScene.rgb == img.rgb);
  ASSERT_EQ(fromScene.channels.size(), 7u);
  for (size_t i = 0; i < 7; ++i) EXPECT_EQ(fromScene.channels[i].values, img.channels[i].values);
  // --aov '' drops the scene's AOVs.
  CliResult none = runCli("render " + d.file("aov.xml") + " -o " + d.file("none.exr") + " --aov '' --no-progress");
  ASSERT_EQ(none.code, 0) << none.output;
  EXPECT_TRUE(envgi::loadImage(d.file("none.exr")).channels.empty());

  CliResult png = runCli("render " + scene + " -o " + d.file("aov.png") + " --aov dd:depth --no-progress");
  EXPECT_NE(png.code, 0);
  EXPECT_NE(png.output.find("must end in .exr"), std::string::npos) << png.output;
  EXPECT_FALSE(std::filesystem::exists(d.file("aov.png")));
  CliResult badSpec = runCli("render " + scene + " -o " + d.file("x.exr") + " --aov dd:dept --no-progress");
  EXPECT_NE(badSpec.code, 0);
  EXPECT_NE(badSpec.output.find("unknown AOV type 'dept' (did you mean 'depth'?)"), std::string::npos) << badSpec.output;
}

// pixel_format rgba with the environment hidden: the .exr has an A channel, 1 on the sphere and
// 0 in the sky; a .png (alone or beside the .exr) is RGBA with that alpha; an .hdr gets RGB and a
// warning, not an error.
TEST(CliRender, RgbaFilmWritesCoverageAsAlpha) {
  TempDir d;
  std::string text = slurp(tinyScene(d, 16, 4));
  const std::string film = "<film type=\"hdrfilm\">";
  const std::string path = "<integrator type=\"path\">";
  ASSERT_NE(text.find(film), std::string::npos);
  text.replace(text.find(film), film.size(), film + "<string name=\"pixel_format\" value=\"rgba\"/>");
  text.replace(text.find(path), path.size(), path + "<boolean name=\"hide_emitters\" value=\"true\"/>");
  std::ofstream(d.file("rgba.xml")) << text;
  CliResult r = runCli("render " + d.file("rgba.xml") + " -o " + d.file("rgba.exr") + " --no-progress");
  ASSERT_EQ(r.code, 0) << r.output;
  envgi::Image img = envgi::loadImage(d.file("rgba.exr"));
  ASSERT_EQ(img.channels.size(), 1u);
  EXPECT_EQ(img.channels[0].name, "A");
  EXPECT_EQ(img.channels[0].values[0], 0.f) << "the top-left corner sees the hidden sky";
  EXPECT_EQ(img.channels[0].values[15 * 16 + 8], 1.f) << "the bottom row sees the floor";
  // A PNG's colour type (byte 25, in IHDR) is 6 for RGBA, 2 for RGB.
  auto pngColourType = [](const std::string& bytes) { return bytes.size() > 25 ? int(bytes[25]) : -1; };
  CliResult png = runCli("render " + d.file("rgba.xml") + " -o " + d.file("alone.png") + " --no-progress");
  ASSERT_EQ(png.code, 0) << png.output;
  EXPECT_EQ(pngColourType(slurp(d.file("alone.png"))), 6);
  CliResult beside = runCli("render " + d.file("rgba.xml") + " -o " + d.file("rgba.exr") + " --png --no-progress");
  ASSERT_EQ(beside.code, 0) << beside.output;
  EXPECT_EQ(pngColourType(slurp(d.file("rgba.png"))), 6);
  CliResult hdr = runCli("render " + d.file("rgba.xml") + " -o " + d.file("rgba.hdr") + " --no-progress");
  ASSERT_EQ(hdr.code, 0) << hdr.output;
  EXPECT_NE(hdr.output.find("cannot hold: it gets RGB"), std::string::npos) << hdr.output;
}

// Mitsuba's serialized shape: the bunny written as the second mesh of a .serialized file renders
// the same to the bit as the scene's PLY (shape_index 1; the file's other mesh is a triangle).
TEST(CliRender, SerializedMeshRendersAsItsPly) {
  TempDir d;
  const std::string src = std::string(ENVGI_SOURCE_DIR) + "/scenes/";
  envgi::TriangleMesh bunny = envgi::loadPly(src + "meshes/bun_zipper_res2.ply");
  MeshData tri;
  tri.positions = {0, 0, 0, 1, 0, 0, 0, 1, 0};
  tri.indices = {0, 1, 2};
  const std::string file = writeSerialized(d, "meshes.serialized", {tri, meshData(bunny)});
  std::string text = slurp(src + "bunny-sunrise.xml");
  const std::string ply = "<shape type=\"ply\">\n        <string name=\"filename\" value=\"meshes/bun_zipper_res2.ply\"/>";
  ASSERT_NE(text.find(ply), std::string::npos);
  for (const char* dir : {"envmaps/", "meshes/"})
    for (size_t at = text.find(std::string("value=\"") + dir); at != std::string::npos;
         at = text.find(std::string("value=\"") + dir, at + 8))
      text.insert(at + 7, src);
  std::ofstream(d.file("ply.xml")) << text;
  const std::string plyAbs = "<shape type=\"ply\">\n        <string name=\"filename\" value=\"" + src + "meshes/bun_zipper_res2.ply\"/>";
  ASSERT_NE(text.find(plyAbs), std::string::npos);
  text.replace(text.find(plyAbs), plyAbs.size(),
               "<shape type=\"serialized\"><string name=\"filename\" value=\"" + file +
                   "\"/><integer name=\"shape_index\" value=\"1\"/>");
  std::ofstream(d.file("serialized.xml")) << text;
  for (const char* name : {"ply", "serialized"}) {
    CliResult r = runCli(std::string("render ") + d.file(std::string(name) + ".xml") + " -o " +
                         d.file(std::string(name) + ".exr") + " -D res=32 -D spp=4 --threads 1 --no-progress");
    ASSERT_EQ(r.code, 0) << name << ": " << r.output;
  }
  EXPECT_EQ(slurp(d.file("ply.exr")), slurp(d.file("serialized.exr")));
}
