// `envgi view`'s server as a hostile page or a broken client would meet it, over real sockets:
// a foreign Origin or Host is refused, a page that never reads is dropped before the server's
// memory grows, running out of file descriptors does not stop it accepting, and a newer page
// takes the session over.
#include <gtest/gtest.h>
#include <sys/socket.h>

#include <filesystem>
#include <fstream>
#include <regex>
#include <memory>

#include "cli/CliRunner.h"
#include "view/BallScene.h"
#include "view/BrowserDriver.h"

using namespace envgi;
using namespace envgi::test;
using json = nlohmann::json;

namespace {

// A running `envgi view` on a small ball scene of its own.
struct Viewer {
  TempDir dir;
  std::unique_ptr<ViewerProcess> process;
  Child* child = nullptr;
  int port = -1;
  explicit Viewer(const std::string& args = "", const std::string& shell = "") {
    std::string xml = dir.file("ball.xml");
    writeBallScene(xml, 48, 32, "");
    process = std::make_unique<ViewerProcess>(xml, dir.file("view.log"), "--threads 1 " + args, shell);
    child = process->child.get();
    port = process->port;
  }
  std::string log() const { return process->log(); }
  // The server's resident memory, in kB.
  long rssKb() const {
    std::ifstream f("/proc/" + std::to_string(child->pid()) + "/status");
    std::string line;
    while (std::getline(f, line))
      if (line.rfind("VmRSS:", 0) == 0) return std::stol(line.substr(6));
    return -1;
  }
};

std::string upgradeRequest(const std::string& host, const std::string& origin, const std::string& target = "/ws") {
  return "GET " + target + " HTTP/1.1\r\nHost: " + host +
         "\r\nUpgrade: websocket\r\nConnection: Upgrade\r\nSec-WebSocket-Key: dGhlIHNhbXBsZSBub25jZQ==\r\n"
         "Sec-WebSocket-Version: 13\r\n" +
         (origin.empty() ? "" : "Origin: " + origin + "\r\n") + "\r\n";
}

std::string statusLine(const std::string& reply) { return reply.substr(0, reply.find("\r\n")); }

// Reads messages until one of `type` (its JSON), or throws on timeout.
json readUntil(WsConnection& ws, const std::string& type) {
  for (int i = 0; i < 200; ++i) {
    bool binary = false;
    std::string m = ws.read(10, &binary);
    if (binary) continue;
    json j = json::parse(m);
    if (j["type"] == type) return j;
  }
  throw std::runtime_error("no " + type + " message");
}

}  // namespace

// Jupyter's rules: on loopback only a loopback Host (DNS rebinding), and in every mode a
// WebSocket only from the page's own origin.
TEST(ViewServer, AForeignOriginOrHostIsRefused) {
  Viewer v;
  ASSERT_GT(v.port, 0) << v.log();
  const std::string self = "127.0.0.1:" + std::to_string(v.port);
  auto get = [&](const std::string& host) {
    return statusLine(httpRawWithin(v.port, "GET / HTTP/1.1\r\nHost: " + host + "\r\n\r\n", 10));
  };
  EXPECT_EQ(get("evil.example"), "HTTP/1.1 403 Forbidden");
  EXPECT_EQ(get("evil.example:" + std::to_string(v.port)), "HTTP/1.1 403 Forbidden");
  EXPECT_EQ(get("127.0.0.1.evil.example"), "HTTP/1.1 403 Forbidden");
  EXPECT_EQ(get(""), "HTTP/1.1 403 Forbidden");
  EXPECT_EQ(get(self), "HTTP/1.1 200 OK");
  EXPECT_EQ(get("localhost:9000"), "HTTP/1.1 200 OK") << "an SSH tunnel's other port";
  EXPECT_EQ(get("[::1]:8000"), "HTTP/1.1 200 OK");
  EXPECT_EQ(get("LOCALHOST"), "HTTP/1.1 200 OK");
  std::string page = httpRawWithin(v.port, "GET / HTTP/1.1\r\nHost: " + self + "\r\n\r\n", 10);
  EXPECT_NE(page.find("Content-Security-Policy: frame-ancestors 'none'"), std::string::npos);

  // The WebSocket: a foreign page's Origin, an opaque one, or a rebinding Host.
  auto upgrade = [&](const std::string& host, const std::string& origin) {
    return statusLine(httpRawWithin(v.port, upgradeRequest(host, origin), 3));
  };
  EXPECT_EQ(upgrade(self, "http://localhost:9999"), "HTTP/1.1 403 Forbidden");
  EXPECT_EQ(upgrade(self, "http://127.0.0.1:" + std::to_string(v.port + 1)), "HTTP/1.1 403 Forbidden");
  EXPECT_EQ(upgrade(self, "null"), "HTTP/1.1 403 Forbidden");
  EXPECT_EQ(upgrade(self, "https://evil.example"), "HTTP/1.1 403 Forbidden");
  EXPECT_EQ(upgrade("evil.example:" + std::to_string(v.port), "http://evil.example:" + std::to_string(v.port)),
            "HTTP/1.1 403 Forbidden");
  EXPECT_TRUE(v.child->waitForLog("refused a request: WebSocket from a foreign page (Origin 'http://localhost:9999')", 5))
      << v.log();
  EXPECT_NE(v.log().find("refused a request: unknown Host 'evil.example'"), std::string::npos);
  // The page's own origin, and a client that sends none (not a browser), are served.
  {
    WsConnection ws(v.port, "/ws", "http://" + self);
    EXPECT_EQ(json::parse(ws.read(10))["type"], "hello");
  }
  {
    WsConnection ws(v.port, "/ws");
    EXPECT_EQ(json::parse(ws.read(10))["type"], "hello");
  }
}

// Bound wider, the token is asked for, and the Origin is still checked.
TEST(ViewServer, BoundWideTheTokenAndTheOriginAreBothChecked) {
  Viewer v("--host 0.0.0.0");
  ASSERT_GT(v.port, 0) << v.log();
  std::smatch m;
  std::string log = v.log();
  ASSERT_TRUE(std::regex_search(log, m, std::regex(R"(\?token=([0-9a-f]{32}))"))) << log;
  const std::string token = m[1];
  const std::string host = "render-node.example:" + std::to_string(v.port);
  auto status = [&](const std::string& request) { return statusLine(httpRawWithin(v.port, request, 1)); };
  EXPECT_EQ(status("GET / HTTP/1.1\r\nHost: " + host + "\r\n\r\n"), "HTTP/1.1 403 Forbidden");
  EXPECT_EQ(status("GET /?token=" + token + " HTTP/1.1\r\nHost: " + host + "\r\n\r\n"), "HTTP/1.1 200 OK");
  EXPECT_EQ(status(upgradeRequest(host, "http://" + host, "/ws")), "HTTP/1.1 403 Forbidden");
  EXPECT_EQ(status(upgradeRequest(host, "http://evil.example", "/ws?token=" + token)), "HTTP/1.1 403 Forbidden");
  EXPECT_EQ(status(upgradeRequest(host, "http://" + host, "/ws?token=" + token)), "HTTP/1.1 101 Switching Protocols");
}

// With -q the URL is still printed: without it (and its token) the viewer cannot be opened.
TEST(ViewServer, QuietStillPrintsTheUrl) {
  TempDir d;
  std::string xml = d.file("ball.xml");
  writeBallScene(xml, 16, 16, "");
  Child view({ENVGI_CLI_PATH, "-q", "view", xml, "--host", "0.0.0.0", "--port", "0", "--threads", "1"}, d.file("q.log"));
  ASSERT_TRUE(view.waitForLog("?token=", 30)) << view.log();
  view.signal(SIGTERM);
  EXPECT_EQ(view.wait(20), 0) << view.log();
}

// A page that sends and never reads: its replies are bounded, it is dropped, the server's
// memory stays where it was, and the next page is served.
TEST(ViewServer, APageThatNeverReadsIsDropped) {
  Viewer v;
  ASSERT_GT(v.port, 0) << v.log();
  {
    WsConnection warm(v.port, "/ws");
    warm.read(10);
  }
  const long before = v.rssKb();
  int sent = 0;
  {
    WsConnection greedy(v.port, "/ws");
    const std::string bad = R"({"type":"exposure","value":"bright)" + std::string(200, '!') + R"("})";
    while (sent < 400000 && greedy.trySend(bad)) ++sent;
  }
  ASSERT_TRUE(v.child->waitForLog("messages unread; dropping it", 10)) << v.log();
  EXPECT_LT(sent, 400000) << "the server closed the page that did not read";
  const long after = v.rssKb();
#ifndef __SANITIZE_ADDRESS__
  // (Under AddressSanitizer freed memory waits in its quarantine, up to 256 MB: no bound to read.)
  EXPECT_LT(after - before, 32 * 1024) << "kB: " << before << " -> " << after;
#endif
  WsConnection next(v.port, "/ws");
  EXPECT_EQ(json::parse(next.read(10))["type"], "hello");
  bool frame = false;
  for (int i = 0; i < 10 && !frame; ++i) next.read(10, &frame);
  EXPECT_TRUE(frame);
}

// Out of file descriptors, accept fails; the server retries and serves again once some are
// free, instead of never accepting again.
TEST(ViewServer, RunningOutOfDescriptorsDoesNotStopAccepting) {
#ifdef __SANITIZE_ADDRESS__
  // Out of descriptors, the sanitized server's UBSan reports a vptr mismatch in libstdc++'s
  // shared_ptr with no stack (its symbolizer cannot open files then); the release suite, which
  // CI runs first, covers the retry.
  GTEST_SKIP() << "not under the sanitizers: UBSan's vptr check fails once the process is out of descriptors";
#endif
  Viewer v("", "ulimit -n 64; ");
  ASSERT_GT(v.port, 0) << v.log();
  std::vector<int> fds;
  for (int i = 0; i < 100; ++i) {
    int fd = ::socket(AF_INET, SOCK_STREAM, 0);
    sockaddr_in a{};
    a.sin_family = AF_INET;
    a.sin_port = htons(uint16_t(v.port));
    a.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
    if (::connect(fd, reinterpret_cast<sockaddr*>(&a), sizeof a) == 0) fds.push_back(fd); else ::close(fd);
  }
  EXPECT_TRUE(v.child->waitForLog("cannot accept a connection", 10)) << v.log();
  for (int fd : fds) ::close(fd);
  std::string reply;
  for (int i = 0; i < 20 && reply.empty(); ++i)
    reply = httpRawWithin(v.port, "GET / HTTP/1.1\r\nHost: 127.0.0.1\r\n\r\n", 2);
  EXPECT_EQ(statusLine(reply), "HTTP/1.1 200 OK") << v.log();
}

// A second page takes the session over (a new tab, or a page whose socket went silent); the
// first is told so and closed.
TEST(ViewServer, ANewerPageTakesTheSessionOver) {
  Viewer v;
  ASSERT_GT(v.port, 0) << v.log();
  WsConnection first(v.port, "/ws");
  EXPECT_EQ(json::parse(first.read(10))["type"], "hello");
  WsConnection second(v.port, "/ws");
  EXPECT_EQ(json::parse(second.read(10))["type"], "hello");
  json told = readUntil(first, "takenOver");
  EXPECT_EQ(told["message"], "another page took over this session");
  EXPECT_THROW(
      for (int i = 0; i < 100; ++i) first.read(5), beast::system_error);
  bool frame = false;
  for (int i = 0; i < 10 && !frame; ++i) second.read(10, &frame);
  EXPECT_TRUE(frame);
  EXPECT_TRUE(v.child->waitForLog("a new page took over the session", 5));
}
