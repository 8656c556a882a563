// `envgi view` in a real browser: headless Chromium (Debian's `chromium`, installed by
// scripts/install-deps.sh) opens the page over the DevTools protocol; the first frame comes,
// a mouse drag orbits (a new frame, from the new camera), the exposure slider re-tones, "Save
// EXR" writes a readable file beside the scene, a second page takes over, bad messages get
// error replies, and Ctrl-C stops the server cleanly. No display, no network.
#include <gtest/gtest.h>

#include <filesystem>
#include <regex>

#include "cli/CliRunner.h"
#include "image/Image.h"
#include "view/BallScene.h"
#include "view/BrowserDriver.h"

using namespace envgi;
using namespace envgi::test;
using json = nlohmann::json;
namespace fs = std::filesystem;

namespace {

std::string writeScene(const TempDir& d) {
  std::string xml = d.file("ball.xml");
  writeBallScene(xml, 96, 64, std::string(ENVGI_SOURCE_DIR) + "/scenes/envmaps/studio.hdr");
  return xml;
}

}  // namespace

TEST(ViewBrowser, OrbitExposureSaveInHeadlessChromium) {
  TempDir d;
  std::string scene = writeScene(d);
  Child view({ENVGI_CLI_PATH, "view", scene, "--port", "0", "--threads", "2", "--max-spp", "256"}, d.file("view.log"));
  ASSERT_TRUE(view.waitForLog("view: open http://", 30)) << view.log();
  int port = printedPort(view.log());
  ASSERT_GT(port, 0) << view.log();

  Browser browser(d.path.string());
  DevTools& page = browser.page();
  browser.navigate("http://127.0.0.1:" + std::to_string(port) + "/");

  // The first frame, then a drag across the image: a frame from camera version >= 1 that differs.
  ASSERT_TRUE(page.waitFor("window.envgiTest !== undefined && envgiTest.frames >= 1", 30)) << view.log();
  json first = page.eval("envgiTest.lastMeta");
  EXPECT_EQ(first["width"], 96);
  EXPECT_EQ(first["cameraVersion"], 0);
  double hash0 = page.eval("envgiTest.lastHash").get<double>();
  json rect = page.eval("(() => { const r = document.getElementById('frame').getBoundingClientRect();"
                        " return [r.left + r.width / 2, r.top + r.height / 2]; })()");
  double x = rect[0], y = rect[1];
  page.mouse("mousePressed", x, y);
  for (int i = 1; i <= 10; ++i) page.mouse("mouseMoved", x + 8 * i, y);
  page.mouse("mouseReleased", x + 80, y);
  ASSERT_TRUE(page.waitFor("envgiTest.cameraSent >= 1 && envgiTest.lastMeta.cameraVersion >= 1", 30))
      << page.eval("JSON.stringify(envgiTest)").dump() << view.log();
  EXPECT_NE(page.eval("envgiTest.lastHash").get<double>(), hash0) << "the orbit changed the picture";
  EXPECT_TRUE(page.eval("envgiTest.latencyMs !== null && envgiTest.latencyMs > 0") == true)
      << "the page reports the time from a move to its frame";

  // Exposure: the slider's value comes back on the next frame.
  page.eval("(() => { const e = document.getElementById('exposure'); e.value = '2';"
            " e.dispatchEvent(new Event('input')); })()");
  EXPECT_TRUE(page.waitFor("envgiTest.lastMeta.exposure === 2", 30));

  // Save: a readable EXR beside the scene, named in the page (of the full film, once the view
  // has settled: the last camera the page sent is the frame's, the move's preview integrator
  // has given way to the page's own, and the coarse first frame to the full one; a slow build
  // showed a full frame of an earlier camera, then the last camera's coarse one was saved).
  ASSERT_TRUE(page.waitFor("envgiTest.lastMeta.cameraVersion === envgiTest.cameraSent && "
                           "envgiTest.lastMeta.integrator === document.getElementById('integrator').value && "
                           "envgiTest.lastMeta.width === 96",
                           30))
      << page.eval("JSON.stringify(envgiTest)").dump() << view.log();
  page.eval("document.getElementById('save').click()");
  ASSERT_TRUE(page.waitFor("envgiTest.saved !== null", 30)) << view.log();
  std::string saved = page.eval("envgiTest.saved");
  EXPECT_EQ(fs::path(saved).parent_path(), d.path);
  Image img = loadImage(saved);
  EXPECT_EQ(img.width, 96);
  EXPECT_EQ(img.height, 64);

  // A noise threshold from the page: adaptive sampling stops the converged pixels (the mean
  // samples a pixel fall below the passes run), and the panel says how many still sample.
  page.eval("(() => { const e = document.getElementById('noiseThreshold'); e.value = '0.1';"
            " e.dispatchEvent(new Event('change')); })()");
  ASSERT_TRUE(page.waitFor("envgiTest.lastMeta.adaptive === true && (envgiTest.lastMeta.converged ||"
                           " envgiTest.lastMeta.spp === 256)", 60))
      << page.eval("JSON.stringify(envgiTest.lastMeta)").dump() << view.log();
  EXPECT_LT(page.eval("envgiTest.lastMeta.meanSpp").get<double>(), 0.5 * 256);
  EXPECT_NE(page.eval("document.getElementById('stats').textContent").get<std::string>().find("adaptive"),
            std::string::npos);

  // The value under the cursor: the film's HDR value, shown in the panel.
  page.mouse("mouseMoved", x, y);
  EXPECT_TRUE(page.waitFor("document.getElementById('pixel').textContent.includes('luminance')", 10));
  // Pause holds the samples; the panel says so.
  page.eval("document.getElementById('pause').click()");
  EXPECT_TRUE(page.waitFor("envgiTest.lastMeta.paused === true", 30)) << view.log();
  page.eval("document.getElementById('pause').click()");
  EXPECT_TRUE(page.waitFor("envgiTest.lastMeta.paused === false", 30)) << view.log();
  // Arrow keys in a dropdown are the dropdown's: no orbit.
  const int sentBefore = page.eval("envgiTest.cameraSent");
  page.eval("document.getElementById('tonemap').focus()");
  page.call("Input.dispatchKeyEvent", {{"type", "keyDown"}, {"key", "ArrowLeft"}, {"code", "ArrowLeft"},
                                       {"windowsVirtualKeyCode", 37}});
  page.call("Input.dispatchKeyEvent", {{"type", "keyUp"}, {"key", "ArrowLeft"}, {"code", "ArrowLeft"},
                                       {"windowsVirtualKeyCode", 37}});
  std::this_thread::sleep_for(std::chrono::milliseconds(100));
  EXPECT_EQ(page.eval("envgiTest.cameraSent"), sentBefore);
  page.eval("document.activeElement.blur()");

  EXPECT_EQ(page.eval("envgiTest.errors.length"), 0) << page.eval("JSON.stringify(envgiTest.errors)").dump();
  page.call("Runtime.evaluate", {{"expression", "1"}});  // drain pending events
  EXPECT_TRUE(page.pageErrors().empty()) << page.pageErrors().front();

  // A second page takes the session over; the first says so and does not fight back.
  {
    WsConnection second(port, "/ws");
    json m = json::parse(second.read(10));
    EXPECT_EQ(m["type"], "hello");
    EXPECT_TRUE(page.waitFor("document.getElementById('stats').textContent === 'another page has this session'", 10))
        << page.eval("document.getElementById('stats').textContent").dump();
    std::this_thread::sleep_for(std::chrono::milliseconds(1500));
    EXPECT_EQ(page.eval("envgiTest.connects"), 1) << "a page taken over does not reconnect";
  }
  EXPECT_TRUE(view.waitForLog("a new page took over the session", 10));

  // Closing the browser drops the socket; the server goes on.
  browser.process().signal(SIGKILL);
  {
    // Bad messages from a new client: error replies, the server keeps serving.
    WsConnection ws(port, "/ws");
    json hello = json::parse(ws.read(10));
    EXPECT_EQ(hello["type"], "hello");
    ws.send("{{{ not json");
    ws.send(R"({"type":"exposure","value":"bright"})");
    int errors = 0;
    bool gotFrame = false;
    for (int i = 0; i < 20 && (errors < 2 || !gotFrame); ++i) {
      bool binary = false;
      std::string m = ws.read(10, &binary);
      if (binary) {
        gotFrame = true;
        ws.send(R"({"type":"next"})");
        continue;
      }
      json j = json::parse(m);
      if (j["type"] == "error") ++errors;
    }
    EXPECT_EQ(errors, 2);
    EXPECT_TRUE(gotFrame);
  }
  // The page is served only at / ; nothing else of the disk.
  EXPECT_EQ(httpGet(port, "/../../etc/passwd", nullptr), 404);
  EXPECT_EQ(httpGet(port, "/ball.xml", nullptr), 404);

  // Ctrl-C: one line, exit 0.
  view.signal(SIGINT);
  EXPECT_EQ(view.wait(20), 0) << view.log();
  EXPECT_NE(view.log().find("SIGINT received, stopping"), std::string::npos) << view.log();
}

// Bound wider than loopback, every request needs the token printed at start.
TEST(ViewBrowser, WiderBindingRequiresTheToken) {
  TempDir d;
  std::string scene = writeScene(d);
  Child view({ENVGI_CLI_PATH, "view", scene, "--host", "0.0.0.0", "--port", "0", "--threads", "1"}, d.file("v.log"));
  ASSERT_TRUE(view.waitForLog("view: open http://", 30)) << view.log();
  std::smatch m;
  std::string log = view.log();
  ASSERT_TRUE(std::regex_search(log, m, std::regex(R"(:([0-9]+)/\?token=([0-9a-f]{32}))"))) << log;
  int port = std::stoi(m[1]);
  std::string token = m[2];
  EXPECT_EQ(httpGet(port, "/", nullptr), 403);
  EXPECT_EQ(httpGet(port, "/?token=wrong", nullptr), 403);
  std::string body;
  EXPECT_EQ(httpGet(port, "/?token=" + token, &body), 200);
  EXPECT_NE(body.find("envgi view"), std::string::npos);
  view.signal(SIGTERM);
  EXPECT_EQ(view.wait(20), 0) << view.log();
}

// Requests other than the page's GET get the status an HTTP client expects: HEAD the page's
// headers without its body, another method 405 with Allow, a header past Beast's 8 KiB limit
// 431, a request line that is not HTTP 400.
TEST(ViewBrowser, OtherRequestsGetTheirHttpStatus) {
  TempDir d;
  std::string scene = writeScene(d);
  Child view({ENVGI_CLI_PATH, "view", scene, "--port", "0", "--threads", "1"}, d.file("v.log"));
  ASSERT_TRUE(view.waitForLog("view: open http://", 30)) << view.log();
  const int port = printedPort(view.log());
  ASSERT_GT(port, 0) << view.log();
  std::string page;
  ASSERT_EQ(httpGet(port, "/", &page), 200);

  std::string head = httpRaw(port, "HEAD / HTTP/1.1\r\nHost: 127.0.0.1\r\n\r\n");
  EXPECT_EQ(head.rfind("HTTP/1.1 200", 0), 0u) << head;
  EXPECT_NE(head.find("Content-Length: " + std::to_string(page.size()) + "\r\n"), std::string::npos) << head;
  EXPECT_EQ(head.size(), head.find("\r\n\r\n") + 4) << "a HEAD reply has no body";

  std::string post = httpRaw(port, "POST / HTTP/1.1\r\nHost: 127.0.0.1\r\nContent-Length: 1\r\n\r\nx");
  EXPECT_EQ(post.rfind("HTTP/1.1 405", 0), 0u) << post;
  EXPECT_NE(post.find("Allow: GET, HEAD\r\n"), std::string::npos) << post;

  std::string longTarget = httpRaw(port, "GET /" + std::string(9000, 'a') + " HTTP/1.1\r\nHost: 127.0.0.1\r\n\r\n");
  EXPECT_EQ(longTarget.rfind("HTTP/1.1 431", 0), 0u) << longTarget.substr(0, 200);

  std::string garbage = httpRaw(port, "HELLO\r\n\r\n");
  EXPECT_EQ(garbage.rfind("HTTP/1.1 400", 0), 0u) << garbage;

  // The server is still there for the page.
  EXPECT_EQ(httpGet(port, "/", nullptr), 200);
  view.signal(SIGTERM);
  EXPECT_EQ(view.wait(20), 0) << view.log();
}

// Bad start-up arguments are one error line and a non-zero exit, before anything listens.
TEST(ViewBrowser, BadArgumentsAreOneErrorLine) {
  TempDir d;
  std::string scene = writeScene(d);
  for (std::string bad : {"--host not-an-address", "--integrator bdpt", "--strategy magic", "--port 70000", "--device tpu",
                          "--noise-threshold -1", "--noise-threshold nan", "--min-spp 1"}) {
    CliResult r = runCli("view " + scene + " " + bad);
    EXPECT_NE(r.code, 0) << bad;
    EXPECT_NE(r.output.find("error"), std::string::npos) << bad << ": " << r.output;
    EXPECT_EQ(r.output.find("view: open"), std::string::npos) << bad << ": " << r.output;
  }
  CliResult missing = runCli("view " + d.file("absent.xml"));
  EXPECT_NE(missing.code, 0);
}

// Another site's page in the same browser (another localhost port) tries to drive the viewer:
// its WebSocket is refused (the Origin is not the viewer's own) before any message, and a
// rebound name (evil.example resolving to 127.0.0.1) gets 403 for the page itself.
TEST(ViewBrowser, AForeignPageCannotDriveTheViewer) {
  TempDir d;
  ViewerProcess viewer(writeScene(d), d.file("view.log"), "--threads 1");
  Child& view = *viewer.child;
  const int port = viewer.port;
  ASSERT_GT(port, 0) << viewer.log();
  OnePageServer foreign(R"(<!doctype html><script>
window.result = { opened: false, messages: 0, closed: false };
const ws = new WebSocket("ws://127.0.0.1:)" + std::to_string(port) + R"(/ws");
ws.onopen = () => { result.opened = true; ws.send(JSON.stringify({ type: "save" })); };
ws.onmessage = () => { result.messages += 1; };
ws.onclose = () => { result.closed = true; };
</script>)");
  Browser browser(d.path.string(), {"--host-resolver-rules=MAP evil.example 127.0.0.1"});
  DevTools& page = browser.page();
  browser.navigate("http://localhost:" + std::to_string(foreign.port()) + "/");
  ASSERT_TRUE(page.waitFor("window.result !== undefined && result.closed", 20)) << view.log();
  EXPECT_EQ(page.eval("result.opened"), false);
  EXPECT_EQ(page.eval("result.messages"), 0);
  EXPECT_TRUE(view.waitForLog("refused a request: WebSocket from a foreign page (Origin 'http://localhost:", 10))
      << view.log();
  EXPECT_FALSE(std::filesystem::exists(d.file("ball-view-1.exr"))) << "the foreign page saved nothing";

  // DNS rebinding: the browser's own origin is evil.example, so the Origin matches the Host;
  // the Host is what gives it away.
  browser.navigate("http://evil.example:" + std::to_string(port) + "/");
  EXPECT_TRUE(page.waitFor("document.body !== null && document.body.textContent.includes(\"unknown Host 'evil.example:\")",
                           20))
      << page.eval("document.body ? document.body.textContent : ''").dump() << view.log();
  EXPECT_EQ(page.eval("window.envgiTest === undefined"), true) << "the viewer's page was not served";
  view.signal(SIGTERM);
  EXPECT_EQ(view.wait(20), 0) << view.log();
}

namespace {

double median(std::vector<double> v) {
  if (v.empty()) return -1.0;
  std::sort(v.begin(), v.end());
  return v.size() % 2 ? v[v.size() / 2] : 0.5 * (v[v.size() / 2 - 1] + v[v.size() / 2]);
}

// The viewer's budgets as the page sees them, printed (a time on a shared machine is a
// measure, not a pass mark): page open to first frame, single moves to their first frame, and
// frames a second while orbiting continuously.
void measureViewport(const std::string& sceneFile, const std::string& name) {
  TempDir d;
  Child view({ENVGI_CLI_PATH, "view", std::string(ENVGI_SOURCE_DIR) + "/scenes/" + sceneFile, "-D", "res=256",
              "--integrator", "path", "--port", "0"},
             d.file("view.log"));
  ASSERT_TRUE(view.waitForLog("view: open http://", 60)) << view.log();
  Browser browser(d.path.string());
  DevTools& page = browser.page();
  // The server is running and warm (its first film rendered for no page): what a reload costs.
  std::this_thread::sleep_for(std::chrono::milliseconds(500));
  browser.navigate("http://127.0.0.1:" + std::to_string(printedPort(view.log())) + "/");
  ASSERT_TRUE(page.waitFor("window.envgiTest !== undefined && envgiTest.frames >= 1", 30)) << view.log();
  const double firstFrame = page.eval("envgiTest.frameTimes[0]").get<double>();

  // Single moves, each after the last one's frame: the time to the first frame of the move.
  std::vector<double> moves;
  for (int i = 0; i < 15; ++i) {
    // The page sends a move on its next animation frame, so wait for that send before waiting
    // for its frame: a refinement frame of the last camera must not count as the answer.
    const int sent = page.eval("envgiTest.cameraSent");
    const int measured = page.eval("envgiTest.latencies.length");
    page.eval("envgiTest.orbit(12, 0)");
    ASSERT_TRUE(page.waitFor("envgiTest.cameraSent > " + std::to_string(sent) +
                                 " && envgiTest.lastMeta.cameraVersion === envgiTest.cameraSent && "
                                 "envgiTest.latencies.length > " + std::to_string(measured),
                             10))
        << view.log();
    moves.push_back(page.eval("envgiTest.latencyMs").get<double>());
    std::this_thread::sleep_for(std::chrono::milliseconds(150));
  }
  // A continuous orbit, a move every animation frame for 3 s.
  json orbit = page.eval(R"((async () => {
    const t0 = performance.now(), f0 = envgiTest.frames;
    envgiTest.latencies = [];
    while (performance.now() - t0 < 3000) { envgiTest.orbit(4, 0); await new Promise(r => requestAnimationFrame(r)); }
    return { frames: envgiTest.frames - f0, seconds: (performance.now() - t0) / 1000, latencies: envgiTest.latencies };
  })())");
  std::vector<double> orbitLatency = orbit["latencies"].get<std::vector<double>>();
  const double fps = orbit["frames"].get<double>() / orbit["seconds"].get<double>();
  std::printf("viewer budget, %s path 256x256: page open -> first frame %.0f ms; move -> frame median %.1f ms "
              "(%zu moves); orbiting %.1f frames/s, move -> frame median %.1f ms\n",
              name.c_str(), firstFrame, median(moves), moves.size(), fps, median(orbitLatency));
  EXPECT_GT(orbit["frames"].get<int>(), 0);
  EXPECT_EQ(page.eval("envgiTest.errors.length"), 0);
  view.signal(SIGTERM);
  EXPECT_EQ(view.wait(20), 0) << view.log();
}

}  // namespace

TEST(ViewBrowser, ViewportBudgetsCornellBox) { measureViewport("cornell-box.xml", "cornell-box"); }
TEST(ViewBrowser, ViewportBudgetsBuddha) { measureViewport("buddha.xml", "buddha"); }
