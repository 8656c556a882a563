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
#include <fstream>
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

// A WebSocket to ws://127.0.0.1:port/path, synchronous.
class WsConnection {
 public:
  WsConnection(int port, const std::string& path) : ws_(ioc_) {
    beast::get_lowest_layer(ws_).connect(
        tcp::endpoint(net::ip::make_address("127.0.0.1"), static_cast<unsigned short>(port)));
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

}  // namespace envgi::test
