// The viewer's session without a browser: frames come one per request, the page's messages
// change what is rendered, and bad messages are errors that change nothing.
#include <gtest/gtest.h>

#include <chrono>
#include <atomic>
#include <condition_variable>
#include <filesystem>
#include <fstream>
#include <mutex>
#include <nlohmann/json.hpp>

#include "cli/CliRunner.h"
#include "scene/SceneLoader.h"
#include "view/ViewSession.h"
#include "view/ViewSessionProbe.h"

using namespace envgi;
using json = nlohmann::json;
using test::frameWhere;
using test::makeSession;
using test::meanOfImage;
using test::Sink;

namespace {

// The error a message gets, or "" when the session takes it.
std::string errorOfMessage(ViewSession& session, const std::string& message) {
  try {
    session.handle(message);
  } catch (const std::runtime_error& e) {
    return e.what();
  }
  return "";
}

// A started session on the scene file xml, one thread, up to maxSpp samples a pixel.
std::unique_ptr<ViewSession> startOn(const std::string& xml, int maxSpp, Sink& sink) {
  auto scene = std::make_unique<Scene>();
  loadScene(xml, {}, *scene);
  ViewOptions vo;
  vo.threads = 1;
  vo.maxSpp = maxSpp;
  auto session = std::make_unique<ViewSession>(std::move(scene), xml, vo);
  session->start([&sink](ViewFrame f) { sink(std::move(f)); });
  return session;
}

// What the session's "save" wrote.
Image savedImage(ViewSession& session) { return loadImage(json::parse(session.handle(R"({"type":"save"})"))["path"]); }

}  // namespace

TEST(ViewSession, FramesComeOnRequestAndFollowTheControls) {
  test::TempDir d;
  Sink sink;
  auto session = makeSession(d.path.string(), sink);
  json hello = json::parse(session->hello());
  EXPECT_EQ(hello["type"], "hello");
  EXPECT_EQ(hello["width"], 24);
  EXPECT_EQ(hello["integrator"], "path");

  std::string jpeg;
  json f1 = sink.waitFor(0, &jpeg);
  EXPECT_EQ(f1["type"], "frame");
  EXPECT_EQ(f1["width"], 24);
  EXPECT_GE(f1["spp"].get<int>(), 1);
  ASSERT_GE(jpeg.size(), 4u);
  EXPECT_EQ((unsigned char)jpeg[0], 0xFF) << "a JPEG starts with FF D8";
  EXPECT_EQ((unsigned char)jpeg[1], 0xD8);
  // One frame in flight: nothing more arrives until the page asks.
  std::this_thread::sleep_for(std::chrono::milliseconds(200));
  {
    std::lock_guard<std::mutex> l(sink.m);
    EXPECT_EQ(sink.frames.size(), 1u);
  }
  // Exposure re-encodes without re-rendering: the next frame says so.
  EXPECT_EQ(session->handle(R"({"type":"exposure","value":2})"), "");
  session->requestFrame();
  json f2 = sink.waitFor(1);
  EXPECT_EQ(f2["exposure"], 2.0);
  // Frames until one satisfies pred (the renderer may still send frames of the old state).
  auto until = [&](auto pred) {
    json f;
    for (int i = 0; i < 50; ++i) {
      size_t n;
      {
        std::lock_guard<std::mutex> l(sink.m);
        n = sink.frames.size();
      }
      session->requestFrame();
      f = sink.waitFor(n);
      if (f.is_null() || pred(f)) break;
    }
    return f;
  };
  // A camera move restarts accumulation and carries its version.
  session->handle(R"({"type":"camera","origin":[0,1,4],"target":[0,0,0],"up":[0,1,0],"version":7})");
  json f3 = until([](const json& f) { return f["cameraVersion"] == 7; });
  EXPECT_EQ(f3["cameraVersion"], 7);
  EXPECT_LE(f3["spp"].get<int>(), 16);
  // Resolution and integrator changes.
  session->handle(R"({"type":"resolution","scale":0.5})");
  session->handle(R"({"type":"integrator","value":"direct"})");
  session->handle(R"({"type":"strategy","value":"uniform"})");
  json f4 = until([](const json& f) { return f["width"] == 12 && f["integrator"] == "direct"; });
  EXPECT_EQ(f4["width"], 12);
  EXPECT_EQ(f4["height"], 8);
  EXPECT_EQ(f4["integrator"], "direct");
  EXPECT_EQ(f4["strategy"], "uniform");
  // Save writes an EXR beside the scene, and the reply names it.
  json saved = json::parse(session->handle(R"({"type":"save"})"));
  EXPECT_EQ(saved["type"], "saved");
  std::string path = saved["path"];
  EXPECT_EQ(std::filesystem::path(path).parent_path(), d.path);
  Image img = loadImage(path);
  EXPECT_EQ(img.width, 12);
  session->stop();
}

TEST(ViewSession, BadMessagesAreErrorsAndChangeNothing) {
  test::TempDir d;
  Sink sink;
  auto session = makeSession(d.path.string(), sink);
  auto errorOf = [&](const std::string& m) { return errorOfMessage(*session, m); };
  EXPECT_EQ(errorOf("not json"), "malformed message (not a JSON object with a 'type')");
  EXPECT_EQ(errorOf("[1,2]"), "malformed message (not a JSON object with a 'type')");
  EXPECT_EQ(errorOf(R"({"type":"teleport"})"), "unknown message type 'teleport'");
  EXPECT_EQ(errorOf(R"({"type":"exposure","value":99})"), "exposure: 'value' must be in [-20, 20]");
  EXPECT_NE(errorOf(R"({"type":"exposure","value":"bright"})").find("exposure: "), std::string::npos);
  EXPECT_EQ(errorOf(R"({"type":"camera","origin":[0,0,1],"target":[0,0,1],"up":[0,1,0]})"),
            "camera: origin and target must be apart");
  EXPECT_EQ(errorOf(R"({"type":"camera","origin":[0,0],"target":[0,0,1],"up":[0,1,0]})"),
            "camera: 'origin' must be 3 numbers");
  EXPECT_NE(errorOf(R"({"type":"strategy","value":"nope"})").find("unknown strategy 'nope'"), std::string::npos);
  EXPECT_NE(errorOf(R"({"type":"integrator","value":"bdpt"})").find("unknown integrator 'bdpt'"), std::string::npos);
  EXPECT_EQ(errorOf(R"({"type":"environment","rotation":10,"scale":-1})"),
            "environment: 'scale' must be in [0, 10000]");
  EXPECT_EQ(errorOf(R"({"type":"resolution","scale":9})"), "resolution: 'scale' must be in [0.1, 2]");
  // Numbers beyond a float's or an int's range are refused before any conversion (the
  // conversions were undefined behaviour; UBSan showed the version's).
  EXPECT_EQ(errorOf(R"({"type":"exposure","value":1e300})"), "exposure: 'value' must be in [-20, 20]");
  EXPECT_EQ(errorOf(R"({"type":"camera","origin":[1e300,0,1],"target":[0,0,0],"up":[0,1,0]})"),
            "camera: 'origin' must be finite");
  EXPECT_EQ(errorOf(R"({"type":"camera","origin":[0,1,4],"target":[0,0,0],"up":[0,1,0],"version":1e300})"),
            "camera: 'version' must be a non-negative integer");
  // The session still renders what it rendered before.
  json f = sink.waitFor(0);
  EXPECT_EQ(f["exposure"], 0.0);
  EXPECT_EQ(f["integrator"], "path");
  EXPECT_EQ(f["width"], 24);
}

// Switching back to an integrator used before keeps its preparation (the grid's photon maps):
// what "grid while the camera moves" relies on. A strategy change drops them all.
TEST(ViewSession, SwitchingBackReusesThePreparedIntegrator) {
  test::TempDir d;
  Sink sink;
  auto session = makeSession(d.path.string(), sink);
  auto showing = [&](const std::string& integrator, const std::string& strategy) {
    for (int i = 0; i < 200; ++i) {
      size_t n;
      {
        std::lock_guard<std::mutex> l(sink.m);
        n = sink.frames.size();
      }
      session->requestFrame();
      json f = sink.waitFor(n);
      if (f.is_null() || (f["integrator"] == integrator && f["strategy"] == strategy)) return;
    }
    ADD_FAILURE() << "no frame from " << integrator;
  };
  showing("path", "product");
  int base = session->preparations();
  session->handle(R"({"type":"integrator","value":"grid"})");
  showing("grid", "product");
  EXPECT_EQ(session->preparations(), base + 1);
  for (int i = 0; i < 2; ++i) {
    session->handle(R"({"type":"integrator","value":"path"})");
    session->handle(R"({"type":"camera","origin":[0,1.5,4],"target":[0,0,0],"up":[0,1,0]})");
    showing("path", "product");
    session->handle(R"({"type":"integrator","value":"grid"})");
    showing("grid", "product");
  }
  EXPECT_EQ(session->preparations(), base + 1) << "path and grid were both kept";
  session->handle(R"({"type":"strategy","value":"importance"})");
  showing("grid", "importance");
  EXPECT_EQ(session->preparations(), base + 2) << "a new strategy makes the grid anew";
}

// `envgi view --device cuda` hands the session the GPU's preparer; the session makes every
// executor through it (here a counting stand-in over the CPU's), and a camera move reuses it.
TEST(ViewSession, ExecutorsComeFromTheInjectedPreparer) {
  test::TempDir d;
  Sink sink;
  auto calls = std::make_shared<std::atomic<int>>(0);
  ViewOptions vo;
  vo.prepare = [calls](const Scene& s, const EmbreeAccel& accel, const RenderOptions& ro) {
    ++*calls;
    return prepareRender(s, accel, ro);
  };
  auto session = makeSession(d.path.string(), sink, vo);
  session->requestFrame();
  EXPECT_FALSE(sink.waitFor(0).is_null());
  session->handle(R"({"type":"camera","origin":[0,1.5,4],"target":[0,0,0],"up":[0,1,0]})");
  session->requestFrame();
  EXPECT_FALSE(sink.waitFor(1).is_null());
  EXPECT_EQ(calls->load(), 1) << "the camera move restarted the executor";
  session->handle(R"({"type":"integrator","value":"direct"})");
  for (size_t n = 2; n < 200; ++n) {
    session->requestFrame();
    json f = sink.waitFor(n);
    if (f.is_null() || f["integrator"] == "direct") break;
  }
  EXPECT_EQ(calls->load(), 2);
  EXPECT_EQ(session->preparations(), calls->load());
}


// A noise threshold (from the command line, then from the page) stops refining the pixels
// that converged; the image divides each pixel by its own samples, so it agrees with a full
// render; a new threshold starts over; SPPM, which cannot mask pixels, ignores it.
TEST(ViewSession, AdaptiveSamplingStopsRefiningConvergedPixels) {
  test::TempDir d;
  Sink sink;
  ViewOptions vo;
  vo.noiseThreshold = 0.1f;
  vo.adaptiveMinSpp = 4;
  auto session = makeSession(d.path.string(), sink, vo, 256);
  json hello = json::parse(session->hello());
  EXPECT_FLOAT_EQ(hello["noiseThreshold"].get<float>(), 0.1f);
  EXPECT_EQ(hello["minSpp"], 4);

  json done = frameWhere(*session, sink, [](const json& f) { return f["converged"] == true; });
  ASSERT_FALSE(done.is_null());
  EXPECT_TRUE(done["adaptive"].get<bool>());
  EXPECT_EQ(done["sampling"].get<double>(), 0.0);
  EXPECT_LT(done["spp"].get<int>(), 256) << "every pixel converged before the viewer's limit";
  EXPECT_GE(done["spp"].get<int>(), 4);
  EXPECT_LE(done["meanSpp"].get<double>(), done["spp"].get<double>());
  Image early = loadImage(json::parse(session->handle(R"({"type":"save"})"))["path"]);
  // Converged: no more passes, so no more frames however often the page asks.
  size_t sent = size_t(session->framesSent());
  session->requestFrame();
  std::this_thread::sleep_for(std::chrono::milliseconds(300));
  EXPECT_EQ(size_t(session->framesSent()), sent);

  // Threshold 0 from the page: adaptive sampling off, the film starts over and runs to 256.
  EXPECT_EQ(session->handle(R"({"type":"adaptive","threshold":0})"), "");
  json full = frameWhere(*session, sink, [](const json& f) { return f["spp"] == 256 && f["adaptive"] == false; });
  ASSERT_FALSE(full.is_null());
  EXPECT_EQ(full["meanSpp"].get<double>(), 256.0);
  EXPECT_FALSE(full["converged"].get<bool>());
  Image ref = loadImage(json::parse(session->handle(R"({"type":"save"})"))["path"]);
  ASSERT_EQ(early.rgb.size(), ref.rgb.size());
  EXPECT_NEAR(meanOfImage(early), meanOfImage(ref), 0.05 * meanOfImage(ref))
      << "each stopped pixel is divided by its own samples";

  // Back on, with the minimum from the page; the new film samples from scratch.
  session->handle(R"({"type":"adaptive","threshold":0.1,"minSpp":8})");
  json again = frameWhere(*session, sink, [](const json& f) { return f["converged"] == true; });
  ASSERT_FALSE(again.is_null());
  EXPECT_GE(again["spp"].get<int>(), 8);
  EXPECT_GE(again["meanSpp"].get<double>(), 8.0) << "every pixel takes the minimum before it may stop";
  EXPECT_LT(again["meanSpp"].get<double>(), again["spp"].get<double>()) << "some pixels stopped before others";

  // SPPM samples every pixel each pass: the threshold is kept but not applied.
  session->handle(R"({"type":"integrator","value":"sppm"})");
  json sppm = frameWhere(*session, sink, [](const json& f) { return f["integrator"] == "sppm"; });
  ASSERT_FALSE(sppm.is_null());
  EXPECT_FALSE(sppm["adaptive"].get<bool>());
  EXPECT_GT(sppm["noiseThreshold"].get<double>(), 0.0);
  EXPECT_EQ(sppm["sampling"].get<double>(), 1.0);
}

TEST(ViewSession, BadAdaptiveMessagesAreErrors) {
  test::TempDir d;
  Sink sink;
  auto session = makeSession(d.path.string(), sink);
  auto errorOf = [&](const std::string& m) { return errorOfMessage(*session, m); };
  EXPECT_EQ(errorOf(R"({"type":"adaptive","threshold":-0.1})"), "adaptive: 'threshold' must be in [0, 10]");
  EXPECT_EQ(errorOf(R"({"type":"adaptive","threshold":0.1,"minSpp":1})"),
            "adaptive: 'minSpp' must be an integer in [2, 1000000]");
  EXPECT_EQ(errorOf(R"({"type":"adaptive","threshold":0.1,"minSpp":2.5})"),
            "adaptive: 'minSpp' must be an integer in [2, 1000000]");
  EXPECT_NE(errorOf(R"({"type":"adaptive"})").find("adaptive: "), std::string::npos);
  json hello = json::parse(session->hello());
  EXPECT_EQ(hello["noiseThreshold"], 0.0) << "a refused message changes nothing";
  EXPECT_EQ(hello["minSpp"], 16);
}

// An executor that cannot do what the page asked (here, one that keeps no variance under a
// noise threshold) ends that render with an error message to the page, not the viewer's
// thread; the next setting the page sends renders again.
TEST(ViewSession, AnExecutorThatCannotSampleAdaptivelyIsAnErrorNotACrash) {
  test::TempDir d;
  Sink sink;
  ViewOptions vo;
  vo.noiseThreshold = 0.1f;
  vo.adaptiveMinSpp = 4;
  vo.prepare = [](const Scene& sc, const EmbreeAccel& accel, const RenderOptions& o) {
    RenderOptions plain = o;
    plain.noiseThreshold = 0.f;  // made without the variance a threshold needs
    return prepareRender(sc, accel, plain);
  };
  auto session = makeSession(d.path.string(), sink, vo, 8);
  json err = sink.waitFor(0);
  ASSERT_FALSE(err.is_null());
  EXPECT_EQ(err["type"], "error");
  EXPECT_NE(err["message"].get<std::string>().find("variance"), std::string::npos) << err.dump();
  EXPECT_EQ(session->handle(R"({"type":"adaptive","threshold":0})"), "");
  json f = frameWhere(*session, sink, [](const json& m) { return m["type"] == "frame" && m["spp"] == 8; });
  ASSERT_FALSE(f.is_null());
  EXPECT_FALSE(f["adaptive"].get<bool>());
}

// A page that connects after the render has finished still gets the frame: the film is done,
// so only pageConnected (not a plain request) sends it again.
TEST(ViewSession, APageConnectingAfterTheLastSampleGetsTheFrame) {
  test::TempDir d;
  Sink sink;
  auto session = makeSession(d.path.string(), sink, {}, 4);
  json last = frameWhere(*session, sink, [](const json& f) { return f["spp"] == 4; });
  ASSERT_FALSE(last.is_null());
  size_t sent = size_t(session->framesSent());
  session->requestFrame();
  std::this_thread::sleep_for(std::chrono::milliseconds(300));
  EXPECT_EQ(size_t(session->framesSent()), sent) << "nothing new to send";
  session->pageConnected();
  json again = sink.waitFor(sent);
  ASSERT_FALSE(again.is_null());
  EXPECT_EQ(again["spp"], 4);
}

// An orthographic camera keeps the view's size that to_world's scale gave it when the page moves
// it: a black ball of radius 1 in a 4 x 4 view (scale 2) under a sky of 1 hides pi / 16 of it,
// before and after a move (the move's rigid frame alone would make the view 2 x 2, and the
// ball would hide most of it).
TEST(ViewSession, AnOrthographicCameraKeepsItsScaleWhenMoved) {
  test::TempDir d;
  std::string xml = d.path.string() + "/ortho.xml";
  std::ofstream(xml) << R"(<scene version="3.0.0">
  <integrator type="path"><integer name="max_depth" value="2"/></integrator>
  <sensor type="orthographic">
    <transform name="to_world"><scale x="2" y="2"/><lookat origin="0, 0, 4" target="0, 0, 0" up="0, 1, 0"/></transform>
    <film type="hdrfilm"><integer name="width" value="16"/><integer name="height" value="16"/><rfilter type="box"/></film>
  </sensor>
  <emitter type="constant"><rgb name="radiance" value="1"/></emitter>
  <shape type="sphere"><float name="radius" value="1"/><bsdf type="diffuse"><rgb name="reflectance" value="0"/></bsdf></shape>
</scene>)";
  Sink sink;
  auto session = startOn(xml, 16, sink);
  const double hidden = 1.0 - kPi / 16.0;
  auto meanOfSaved = [&] { return meanOfImage(savedImage(*session)); };
  frameWhere(*session, sink, [](const json& f) { return f["spp"].get<int>() >= 16; });
  EXPECT_NEAR(meanOfSaved(), hidden, 0.03);
  session->handle(R"({"type":"camera","origin":[4,0,0],"target":[0,0,0],"up":[0,1,0],"version":3})");
  frameWhere(*session, sink, [](const json& f) { return f["cameraVersion"] == 3 && f["spp"].get<int>() >= 16; });
  EXPECT_NEAR(meanOfSaved(), hidden, 0.03);
  session->stop();
}

// A crop window stays the same part of the view when the page scales the resolution: the right
// half of an orthographic 4 x 4 view, with a black ball of radius 0.45 in its right half, shows
// 1 - 0.2025 pi / 8 = 0.92 at full and at half resolution (had the window kept its pixels and
// not its share of the film, it would show only sky at half resolution).
TEST(ViewSession, ACropWindowKeepsItsPartOfTheViewAtAnyResolution) {
  test::TempDir d;
  std::string xml = d.path.string() + "/crop.xml";
  std::ofstream(xml) << R"(<scene version="3.0.0">
  <integrator type="path"><integer name="max_depth" value="2"/></integrator>
  <sensor type="orthographic">
    <transform name="to_world"><scale x="2" y="2"/><lookat origin="0, 0, 4" target="0, 0, 0" up="0, 1, 0"/></transform>
    <film type="hdrfilm"><integer name="width" value="32"/><integer name="height" value="32"/>
      <integer name="crop_offset_x" value="16"/><integer name="crop_width" value="16"/><rfilter type="box"/></film>
  </sensor>
  <emitter type="constant"><rgb name="radiance" value="1"/></emitter>
  <shape type="sphere"><point name="center" x="1.5" y="0" z="0"/><float name="radius" value="0.45"/>
    <bsdf type="diffuse"><rgb name="reflectance" value="0"/></bsdf></shape>
</scene>)";
  Sink sink;
  auto session = startOn(xml, 16, sink);
  auto saved = [&] { return savedImage(*session); };
  const double expected = 1.0 - 0.2025 * kPi / 8.0;
  frameWhere(*session, sink, [](const json& f) { return f["spp"].get<int>() >= 16; });
  Image full = saved();
  EXPECT_EQ(full.width, 16);
  EXPECT_NEAR(meanOfImage(full), expected, 0.015);
  session->handle(R"({"type":"resolution","scale":0.5})");
  frameWhere(*session, sink, [](const json& f) { return f["width"] == 8 && f["spp"].get<int>() >= 16; });
  Image half = saved();
  EXPECT_EQ(half.width, 8);
  EXPECT_EQ(half.height, 16);
  EXPECT_NEAR(meanOfImage(half), expected, 0.02);
  session->stop();
}

// The page's resolution control restarts the executor at up to twice the scene's size, which
// resized the film without prepareRender's memory check. A film that would not fit is now an
// error frame that leaves the viewer running, and the scale the film fits at renders again.
TEST(ViewSession, AResolutionWhoseFilmCannotFitIsAnError) {
  test::TempDir d;
  Sink sink;
  ViewOptions vo;
  // The ball scene is 24 x 16: its film (41 bytes a pixel) fits in half of 64 kB at scale 1,
  // not at scale 2 (4 times the pixels).
  vo.memoryBytes = 64.0 * 1024.0;
  auto session = makeSession(d.path.string(), sink, vo, 4);
  ASSERT_FALSE(frameWhere(*session, sink, [](const json& m) { return m["type"] == "frame" && m["spp"] == 4; }).is_null());
  size_t n;
  {
    std::lock_guard<std::mutex> l(sink.m);
    n = sink.frames.size();
  }
  EXPECT_EQ(session->handle(R"({"type":"resolution","scale":2})"), "");
  json err = sink.waitFor(n);
  ASSERT_FALSE(err.is_null());
  EXPECT_EQ(err["type"], "error") << err.dump();
  EXPECT_NE(err["message"].get<std::string>().find("a 48x32 film would take about"), std::string::npos) << err.dump();
  EXPECT_EQ(session->handle(R"({"type":"resolution","scale":1})"), "");
  json f = frameWhere(*session, sink, [](const json& m) { return m["type"] == "frame" && m["spp"] == 4; });
  ASSERT_FALSE(f.is_null());
  EXPECT_EQ(f["width"], 24);
  session->stop();
}
