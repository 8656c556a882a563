// For the viewer's browser test: a child process (envgi view, Chromium) with its output in a
// file, and a minimal Chrome DevTools Protocol client over Boost.Beast (evaluate JavaScript,
// send mouse events, collect console errors and exceptions).
#pragma once

#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <boost/beast/core.hpp>
#include <boost/beast/http.hpp>
#include <boost/beast/websocket.hpp>
#include <chrono>
#include <array>
#include <atomic>
#include <cctype>
#include <cstdlib>
#include <fstream>
#include <functional>
#include <memory>
#include <nlohmann/json.hpp>
#include <sstream>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

namespace envgi::test {

// A child process; killed (SIGKILL) on destruction if still running.
class Child {
 public:
  Child(const std::vector<std::string>& argv, const std::string& logPath) : log_(logPath) {
    pid_ = fork();
    if (pid_ == 0) {
      FILE* f = std::fopen(logPath.c_str(), "w");
      if (f) {
        dup2(fileno(f), 1);
        dup2(fileno(f), 2);
      }
      setpgid(0, 0);  // its own group, so that Chromium's helpers go with it
      std::vector<char*> args;
      for (const std::string& a : argv) args.push_back(const_cast<char*>(a.c_str()));
      args.push_back(nullptr);
      execvp(args[0], args.data());
      _exit(127);
    }
  }
  ~Child() {
    if (pid_ > 0 && !exited_) {
      kill(-pid_, SIGKILL);
      waitpid(pid_, nullptr, 0);
    }
  }
  std::string log() const {
    std::ifstream f(log_);
    std::stringstream s;
    s << f.rdbuf();
    return s.str();
  }
  // Waits until the log contains text (true) or the time is up (false).
  bool waitForLog(const std::string& text, double seconds) const {
    auto end = std::chrono::steady_clock::now() + std::chrono::duration<double>(seconds);
    while (std::chrono::steady_clock::now() < end) {
      if (log().find(text) != std::string::npos) return true;
      std::this_thread::sleep_for(std::chrono::milliseconds(50));
    }
    return false;
  }
  void signal(int sig) { kill(pid_, sig); }
  pid_t pid() const { return pid_; }
  // The exit code, or -1 if it is still running after `seconds` (or died of a signal).
  int wait(double seconds) {
    auto end = std::chrono::steady_clock::now() + std::chrono::duration<double>(seconds);
    while (std::chrono::steady_clock::now() < end) {
      int status = 0;
      if (waitpid(pid_, &status, WNOHANG) == pid_) {
        exited_ = true;
        return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
      }
      std::this_thread::sleep_for(std::chrono::milliseconds(20));
    }
    return -1;
  }

 private:
  pid_t pid_ = -1;
  bool exited_ = false;
  std::string log_;
};

namespace beast = boost::beast;
namespace net = boost::asio;
using tcp = net::ip::tcp;

// GET http://127.0.0.1:port/target; returns the status and fills body.
inline int httpGet(int port, const std::string& target, std::string* body) {
  net::io_context ioc;
  beast::tcp_stream stream(ioc);
  stream.connect(tcp::endpoint(net::ip::make_address("127.0.0.1"), static_cast<unsigned short>(port)));
  beast::http::request<beast::http::empty_body> req(beast::http::verb::get, target, 11);
  req.set(beast::http::field::host, "127.0.0.1");
  beast::http::write(stream, req);
  beast::flat_buffer buf;
  beast::http::response<beast::http::string_body> res;
  beast::http::read(stream, buf, res);
  if (body) *body = res.body();
  beast::error_code ec;
  stream.socket().shutdown(tcp::socket::shutdown_both, ec);
  return int(res.result_int());
}

// Sends `request` as it is to 127.0.0.1:port and returns all the server answers before it
// closes the connection (the viewer closes after each reply).
inline std::string httpRaw(int port, const std::string& request) {
  net::io_context ioc;
  tcp::socket sock(ioc);
  sock.connect(tcp::endpoint(net::ip::make_address("127.0.0.1"), static_cast<unsigned short>(port)));
  net::write(sock, net::buffer(request));
  std::string out;
  beast::error_code ec;
  char buf[4096];
  for (;;) {
    size_t n = sock.read_some(net::buffer(buf), ec);
    out.append(buf, n);
    if (ec) break;
  }
  return out;
}

// Sends `request` to 127.0.0.1:port and returns what comes back within `seconds` (empty if
// nothing does: a server that no longer accepts).
inline std::string httpRawWithin(int port, const std::string& request, double seconds) {
  net::io_context ioc;
  beast::tcp_stream stream(ioc);
  std::string out;
  stream.expires_after(std::chrono::milliseconds(int(seconds * 1000)));
  stream.async_connect(tcp::endpoint(net::ip::make_address("127.0.0.1"), static_cast<unsigned short>(port)),
                       [&](beast::error_code ec) {
                         if (ec) return;
                         net::write(stream.socket(), net::buffer(request), ec);
                       });
  ioc.run();
  ioc.restart();
  auto buf = std::make_shared<std::array<char, 4096>>();
  std::function<void(beast::error_code, size_t)> onRead = [&](beast::error_code ec, size_t n) {
    out.append(buf->data(), n);
    if (!ec) stream.async_read_some(net::buffer(*buf), onRead);
  };
  stream.async_read_some(net::buffer(*buf), onRead);
  ioc.run();
  return out;
}

// A WebSocket to ws://127.0.0.1:port/path, synchronous; origin: the Origin header a browser
// would send (none when empty).
class WsConnection {
 public:
  WsConnection(int port, const std::string& path, const std::string& origin = "") : ws_(ioc_) {
    beast::get_lowest_layer(ws_).connect(
        tcp::endpoint(net::ip::make_address("127.0.0.1"), static_cast<unsigned short>(port)));
    if (!origin.empty())
      ws_.set_option(beast::websocket::stream_base::decorator(
          [origin](beast::websocket::request_type& req) { req.set(beast::http::field::origin, origin); }));
    ws_.handshake("127.0.0.1:" + std::to_string(port), path);
  }
  void send(const std::string& text) {
    ws_.text(true);
    ws_.write(net::buffer(text));
  }
  // The next message (text or binary), or throws after `seconds`.
  std::string read(double seconds, bool* binary = nullptr) {
    // The stream's expiry bounds only asynchronous operations: a synchronous read would wait
    // for ever on a server that sends nothing.
    beast::get_lowest_layer(ws_).expires_after(std::chrono::milliseconds(int(seconds * 1000)));
    beast::flat_buffer buf;
    beast::error_code ec;
    ws_.async_read(buf, [&ec](beast::error_code e, std::size_t) { ec = e; });
    ioc_.restart();
    ioc_.run();
    if (ec) throw beast::system_error(ec);
    if (binary) *binary = ws_.got_binary();
    return beast::buffers_to_string(buf.data());
  }
  // Sends without waiting for any reply; false once the server has closed the connection.
  bool trySend(const std::string& text) {
    beast::error_code ec;
    ws_.text(true);
    ws_.write(net::buffer(text), ec);
    return !ec;
  }

 private:
  net::io_context ioc_;
  beast::websocket::stream<beast::tcp_stream> ws_;
};

// The DevTools protocol on one page: commands by id, events kept for inspection.
class DevTools {
 public:
  DevTools(int port, const std::string& path) : ws_(port, path) {}

  nlohmann::json call(const std::string& method, nlohmann::json params = nlohmann::json::object()) {
    int id = ++nextId_;
    ws_.send(nlohmann::json{{"id", id}, {"method", method}, {"params", params}}.dump());
    for (;;) {
      nlohmann::json m = nlohmann::json::parse(ws_.read(30.0));
      if (m.contains("id") && m["id"] == id) {
        if (m.contains("error")) throw std::runtime_error(method + ": " + m["error"].dump());
        return m["result"];
      }
      note(m);
    }
  }
  // The value of a JavaScript expression in the page.
  nlohmann::json eval(const std::string& expr) {
    nlohmann::json r = call("Runtime.evaluate", {{"expression", expr}, {"returnByValue", true}, {"awaitPromise", true}});
    if (r.contains("exceptionDetails")) throw std::runtime_error("page: " + r["exceptionDetails"].dump());
    return r["result"].contains("value") ? r["result"]["value"] : nlohmann::json();
  }
  // Polls expr until it is true (true) or the time is up (false).
  bool waitFor(const std::string& expr, double seconds) {
    auto end = std::chrono::steady_clock::now() + std::chrono::duration<double>(seconds);
    while (std::chrono::steady_clock::now() < end) {
      if (eval(expr) == true) return true;
      std::this_thread::sleep_for(std::chrono::milliseconds(50));
    }
    return false;
  }
  void mouse(const std::string& type, double x, double y) {
    call("Input.dispatchMouseEvent",
         {{"type", type}, {"x", x}, {"y", y}, {"button", "left"}, {"buttons", type == "mouseReleased" ? 0 : 1},
          {"clickCount", 1}});
  }
  // Console errors and uncaught exceptions the page reported.
  const std::vector<std::string>& pageErrors() const { return errors_; }

 private:
  WsConnection ws_;
  int nextId_ = 0;
  std::vector<std::string> errors_;
  void note(const nlohmann::json& m) {
    std::string method = m.value("method", "");
    if (method == "Runtime.exceptionThrown") errors_.push_back(m["params"].dump());
    if (method == "Runtime.consoleAPICalled" && m["params"].value("type", "") == "error")
      errors_.push_back(m["params"].dump());
    if (method == "Log.entryAdded" && m["params"]["entry"].value("level", "") == "error")
      errors_.push_back(m["params"].dump());
  }
};

// The port a child printed in "http://HOST:PORT/" (or ws://), or -1.
inline int printedPort(const std::string& log) {
  size_t at = log.find("://");
  while (at != std::string::npos) {
    size_t colon = log.find_first_of(":/", at + 3);
    if (colon != std::string::npos && log[colon] == ':') {
      size_t end = colon + 1;
      while (end < log.size() && std::isdigit(static_cast<unsigned char>(log[end]))) ++end;
      if (end > colon + 1) return std::stoi(log.substr(colon + 1, end - colon - 1));
    }
    at = log.find("://", at + 3);
  }
  return -1;
}

// A running `envgi view SCENE --port 0 ARGS` (through bash, after `shell`: ulimit...), its port
// read from the URL it printed (-1 if it printed none within 30 s).
struct ViewerProcess {
  std::unique_ptr<Child> child;
  int port = -1;
  ViewerProcess(const std::string& scene, const std::string& logPath, const std::string& args = "",
                const std::string& shell = "") {
    child = std::make_unique<Child>(
        std::vector<std::string>{"bash", "-c", shell + "exec " + ENVGI_CLI_PATH + " view " + scene + " --port 0 " + args},
        logPath);
    if (child->waitForLog("view: open http://", 30)) port = printedPort(child->log());
  }
  std::string log() const { return child->log(); }
};

inline std::string findChromium() {
  for (const char* name : {"chromium", "chromium-browser", "google-chrome"}) {
    std::string cmd = std::string("command -v ") + name + " >/dev/null 2>&1";
    if (std::system(cmd.c_str()) == 0) return name;
  }
  return "";
}

// Headless Chromium with one blank page, driven over the DevTools protocol. Throws where the
// browser is missing or does not start.
class Browser {
 public:
  Browser(const std::string& dir, const std::vector<std::string>& extraArgs = {}) {
    const std::string chromium = findChromium();
    if (chromium.empty()) throw std::runtime_error("the browser tests need Debian's chromium (scripts/install-deps.sh)");
    std::vector<std::string> argv = {chromium,
                                     "--headless=new",
                                     "--no-sandbox",
                                     "--disable-gpu",
                                     "--no-first-run",
                                     "--remote-debugging-port=0",
                                     "--user-data-dir=" + dir + "/profile",
                                     "--window-size=900,600"};
    argv.insert(argv.end(), extraArgs.begin(), extraArgs.end());
    argv.push_back("about:blank");
    child_ = std::make_unique<Child>(argv, dir + "/chromium.log");
    if (!child_->waitForLog("DevTools listening on ws://", 60)) throw std::runtime_error("chromium: " + child_->log());
    // The port in the line that announces it: other lines may name other URLs first.
    const std::string log = child_->log();
    const int devPort = printedPort(log.substr(log.find("DevTools listening on ws://")));
    std::string list;
    if (httpGet(devPort, "/json/list", &list) != 200) throw std::runtime_error("chromium: no page list");
    std::string pageWs;
    for (const nlohmann::json& t : nlohmann::json::parse(list))
      if (t.value("type", "") == "page") pageWs = t.value("webSocketDebuggerUrl", "");
    if (pageWs.empty()) throw std::runtime_error("chromium: no page in " + list);
    page_ = std::make_unique<DevTools>(devPort, pageWs.substr(pageWs.find('/', 5)));
    page_->call("Runtime.enable");
    page_->call("Log.enable");
    page_->call("Page.enable");
  }
  DevTools& page() { return *page_; }
  Child& process() { return *child_; }
  void navigate(const std::string& url) { page_->call("Page.navigate", {{"url", url}}); }

 private:
  std::unique_ptr<Child> child_;
  std::unique_ptr<DevTools> page_;
};

// A plain HTTP server on 127.0.0.1 that answers every GET with one HTML page: another site's
// page, for the tests where a foreign page tries to drive the viewer.
class OnePageServer {
 public:
  explicit OnePageServer(std::string html) : html_(std::move(html)), acceptor_(ioc_, tcp::endpoint(net::ip::make_address("127.0.0.1"), 0)) {
    thread_ = std::thread([this] { serve(); });
  }
  ~OnePageServer() {
    stop_ = true;
    beast::error_code ec;
    // Wakes the blocking accept.
    tcp::socket s(ioc_);
    s.connect(acceptor_.local_endpoint(), ec);
    thread_.join();
  }
  int port() const { return acceptor_.local_endpoint().port(); }

 private:
  std::string html_;
  net::io_context ioc_;
  tcp::acceptor acceptor_;
  std::thread thread_;
  std::atomic<bool> stop_{false};
  void serve() {
    while (!stop_) {
      beast::error_code ec;
      tcp::socket sock(ioc_);
      acceptor_.accept(sock, ec);
      if (ec || stop_) continue;
      beast::flat_buffer buf;
      beast::http::request<beast::http::string_body> req;
      beast::http::read(sock, buf, req, ec);
      if (ec) continue;
      beast::http::response<beast::http::string_body> res(beast::http::status::ok, 11);
      res.set(beast::http::field::content_type, "text/html");
      res.body() = html_;
      res.prepare_payload();
      res.keep_alive(false);
      beast::http::write(sock, res, ec);
      sock.shutdown(tcp::socket::shutdown_both, ec);
    }
  }
};

}  // namespace envgi::test
