#include "view/ViewServer.h"

#include <spdlog/spdlog.h>

#include <boost/asio/signal_set.hpp>
#include <boost/asio/steady_timer.hpp>
#include <boost/asio/strand.hpp>
#include <boost/beast/core.hpp>
#include <boost/beast/http.hpp>
#include <boost/beast/websocket.hpp>
#include <cctype>
#include <chrono>
#include <deque>
#include <optional>
#include <nlohmann/json.hpp>

#include "view/ViewerPage.h"

namespace envgi {

namespace beast = boost::beast;
namespace http = beast::http;
namespace websocket = beast::websocket;
namespace net = boost::asio;
using tcp = net::ip::tcp;
using Clock = std::chrono::steady_clock;

namespace {

std::string queryValue(const std::string& target, const std::string& key) {
  size_t q = target.find('?');
  if (q == std::string::npos) return "";
  std::string query = target.substr(q + 1);
  size_t pos = 0;
  while (pos <= query.size()) {
    size_t amp = query.find('&', pos);
    std::string kv = query.substr(pos, amp == std::string::npos ? std::string::npos : amp - pos);
    if (kv.rfind(key + "=", 0) == 0) return kv.substr(key.size() + 1);
    if (amp == std::string::npos) break;
    pos = amp + 1;
  }
  return "";
}

std::string pathOf(const std::string& target) { return target.substr(0, target.find('?')); }

std::string lower(std::string s) {
  for (char& c : s) c = char(std::tolower(static_cast<unsigned char>(c)));
  return s;
}

// The name in a Host header, without its port: "[::1]:8000" -> "[::1]", "localhost:9" -> "localhost".
std::string hostName(const std::string& host) {
  if (!host.empty() && host[0] == '[') return lower(host.substr(0, host.find(']') + 1));
  return lower(host.substr(0, host.find(':')));
}

bool isLoopbackName(const std::string& name) {
  return name == "127.0.0.1" || name == "localhost" || name == "[::1]";
}

// Compares without stopping at the first difference, so the time taken says nothing of the token.
bool sameToken(const std::string& a, const std::string& b) {
  unsigned char diff = a.size() == b.size() ? 0 : 1;
  for (size_t i = 0; i < a.size(); ++i) diff |= static_cast<unsigned char>(a[i] ^ (i < b.size() ? b[i] : 0));
  return diff == 0;
}

}  // namespace

class WsClient;

struct ViewServer::Impl {
  ViewSession& session;
  ViewServerOptions opts;
  net::io_context ioc{1};
  tcp::acceptor acceptor{ioc};
  net::signal_set signals{ioc, SIGINT, SIGTERM};
  std::shared_ptr<WsClient> client;  // the one connected page (I/O thread only)
  net::steady_timer acceptRetry{ioc};
  Clock::time_point lastAcceptWarning{};

  Impl(ViewSession& s, const ViewServerOptions& o) : session(s), opts(o) {}
  void accept();
  void shutdown();
  // Why a request may not be served ("" where it may): the token, the Host on loopback, and a
  // WebSocket's Origin.
  std::string refusal(const http::request<http::string_body>& req, bool websocketUpgrade) const;
};

std::string ViewServer::Impl::refusal(const http::request<http::string_body>& req, bool websocketUpgrade) const {
  const std::string target(req.target());
  if (!opts.token.empty() && !sameToken(queryValue(target, "token"), opts.token))
    return "this server needs its token (?token=...)";
  const std::string host(req[http::field::host]);
  // Bound wider, the token is the guard (a rebinding page cannot know it), and the names the
  // machine is reached by are not known here.
  if (opts.token.empty() && !isLoopbackName(hostName(host))) return "unknown Host '" + host + "'";
  if (websocketUpgrade && req.find(http::field::origin) != req.end()) {
    const std::string origin = lower(std::string(req[http::field::origin]));
    if (origin != "http://" + lower(host) && origin != "https://" + lower(host))
      return "WebSocket from a foreign page (Origin '" + std::string(req[http::field::origin]) + "')";
  }
  return "";
}

// One page's WebSocket: reads its messages, writes frames and replies through a bounded queue
// (one write in flight, as Beast requires).
class WsClient : public std::enable_shared_from_this<WsClient> {
 public:
  WsClient(ViewServer::Impl& server, tcp::socket socket) : server_(server), ws_(std::move(socket)) {}

  void start(http::request<http::string_body> req) {
    // Frames are single writes that must go now, not wait for more bytes (Nagle held each
    // frame's JPEG about 40 ms).
    beast::error_code ec;
    beast::get_lowest_layer(ws_).socket().set_option(tcp::no_delay(true), ec);
    auto timeouts = websocket::stream_base::timeout::suggested(beast::role_type::server);
    timeouts.idle_timeout = std::chrono::seconds(server_.opts.idleSeconds);
    timeouts.keep_alive_pings = true;
    ws_.set_option(timeouts);
    ws_.read_message_max(server_.opts.maxMessageBytes);
    ws_.async_accept(req, [self = shared_from_this()](beast::error_code ec) { self->onAccept(ec); });
  }

  void send(std::string text, bool binary) {
    if (closed_) return;
    if (queue_.size() >= server_.opts.maxQueued) {
      spdlog::warn("view: the page left {} messages unread; dropping it", queue_.size());
      drop();
      return;
    }
    queue_.push_back({std::move(text), binary});
    if (queue_.size() == 1) writeNext();
  }

  // Closes the socket at once; what is queued goes when the write in flight ends (it still
  // reads its buffer until then).
  void close() {
    closed_ = true;
    if (!writing_) queue_.clear();
    beast::error_code ec;
    beast::get_lowest_layer(ws_).socket().close(ec);
  }

  // Sends a last message, then closes the WebSocket with `code`.
  void closeWith(const std::string& message, websocket::close_code code) {
    send(message, false);
    closeCode_ = code;
    if (queue_.empty()) finish();
  }

 private:
  struct Out {
    std::string data;
    bool binary;
  };
  ViewServer::Impl& server_;
  websocket::stream<beast::tcp_stream> ws_;
  beast::flat_buffer buffer_;
  std::deque<Out> queue_;
  bool closed_ = false;
  bool writing_ = false;
  std::optional<websocket::close_code> closeCode_;

  void drop() {
    if (server_.client.get() == this) server_.client.reset();
    close();
  }

  void finish() {
    closed_ = true;
    ws_.async_close(*closeCode_, [self = shared_from_this()](beast::error_code) {});
  }

  void onAccept(beast::error_code ec) {
    if (ec) return;
    if (server_.client) {
      // The newer page takes over: a user who opened another tab, or whose page went silent,
      // gets the session without waiting for the old socket's timeout.
      spdlog::info("view: a new page took over the session");
      server_.client->closeWith(
          nlohmann::json{{"type", "takenOver"}, {"message", "another page took over this session"}}.dump(),
          websocket::close_code::policy_error);
      server_.client.reset();
    }
    server_.client = shared_from_this();
    spdlog::info("view: a page connected");
    send(server_.session.hello(), false);
    server_.session.pageConnected();
    read();
  }

  void read() {
    ws_.async_read(buffer_, [self = shared_from_this()](beast::error_code ec, size_t) { self->onRead(ec); });
  }

  void onRead(beast::error_code ec) {
    if (ec) {
      if (server_.client.get() == this) {
        server_.client.reset();
        if (!closed_) spdlog::info("view: the page disconnected ({})", ec.message());
      }
      return;
    }
    if (closed_) return;
    std::string msg = beast::buffers_to_string(buffer_.data());
    buffer_.consume(buffer_.size());
    // A page that was taken over steers nothing; it reads on until its close completes.
    if (server_.client.get() != this) return read();
    try {
      std::string reply = server_.session.handle(msg);
      if (!reply.empty()) send(reply, false);
    } catch (const std::exception& e) {
      spdlog::warn("view: {}", e.what());
      send(nlohmann::json{{"type", "error"}, {"message", e.what()}}.dump(), false);
    }
    if (!closed_) read();
  }

  void writeNext() {
    writing_ = true;
    ws_.binary(queue_.front().binary);
    ws_.async_write(net::buffer(queue_.front().data), [self = shared_from_this()](beast::error_code ec, size_t) {
      self->writing_ = false;
      self->queue_.pop_front();
      if (ec || self->closed_) {  // the read side notices and logs
        self->queue_.clear();
        return;
      }
      if (!self->queue_.empty())
        self->writeNext();
      else if (self->closeCode_)
        self->finish();
    });
  }
};

// One HTTP connection: the page, or the upgrade to the WebSocket.
class HttpConnection : public std::enable_shared_from_this<HttpConnection> {
 public:
  HttpConnection(ViewServer::Impl& server, tcp::socket socket) : server_(server), stream_(std::move(socket)) {}
  void start() {
    stream_.expires_after(std::chrono::seconds(30));
    http::async_read(stream_, buffer_, req_,
                     [self = shared_from_this()](beast::error_code ec, size_t) { self->onRead(ec); });
  }

 private:
  ViewServer::Impl& server_;
  beast::tcp_stream stream_;
  beast::flat_buffer buffer_;
  http::request<http::string_body> req_;

  void onRead(beast::error_code ec) {
    // A request Beast could not read gets its status, as any HTTP server gives one; a closed or
    // timed-out connection gets nothing.
    if (ec == http::error::header_limit)
      return reply(http::status::request_header_fields_too_large, "text/plain", "request header too large\n");
    if (ec == http::error::body_limit) return reply(http::status::payload_too_large, "text/plain", "body too large\n");
    if (ec && ec.category() == http::make_error_code(http::error::bad_method).category() &&
        ec != http::error::end_of_stream && ec != http::error::partial_message)
      return reply(http::status::bad_request, "text/plain", "bad request\n");
    if (ec) return;
    std::string target(req_.target());
    std::string path = pathOf(target);
    const bool upgrade = path == "/ws" && websocket::is_upgrade(req_);
    if (std::string why = server_.refusal(req_, upgrade); !why.empty()) {
      spdlog::warn("view: refused a request: {}", why);
      return reply(http::status::forbidden, "text/plain", "envgi view: " + why + "\n");
    }
    if (upgrade) {
      stream_.expires_never();
      std::make_shared<WsClient>(server_, stream_.release_socket())->start(std::move(req_));
      return;
    }
    if (req_.method() != http::verb::get && req_.method() != http::verb::head)
      return reply(http::status::method_not_allowed, "text/plain", "GET or HEAD only\n");
    if (path == "/" || path == "/index.html") return reply(http::status::ok, "text/html; charset=utf-8", kViewerPage);
    if (path == "/favicon.ico") return reply(http::status::no_content, "text/plain", "");
    reply(http::status::not_found, "text/plain", "not found\n");
  }

  void reply(http::status status, const char* type, std::string body) {
    // A request that could not be read has no version: answer in HTTP/1.1.
    auto res = std::make_shared<http::response<http::string_body>>(status, req_.version() ? req_.version() : 11);
    res->set(http::field::server, "envgi");
    res->set(http::field::content_type, type);
    res->set(http::field::cache_control, "no-store");
    // No other site may frame the page and click its controls, nor a browser guess its type.
    res->set("Content-Security-Policy", "frame-ancestors 'none'");
    res->set("X-Content-Type-Options", "nosniff");
    if (status == http::status::method_not_allowed) res->set(http::field::allow, "GET, HEAD");
    const size_t length = body.size();
    res->body() = std::move(body);
    res->prepare_payload();
    if (req_.method() == http::verb::head) {
      // HEAD: the headers GET would send, Content-Length included, and no body.
      res->body().clear();
      res->content_length(length);
    }
    res->keep_alive(false);
    http::async_write(stream_, *res, [self = shared_from_this(), res](beast::error_code, size_t) {
      beast::error_code ec;
      self->stream_.socket().shutdown(tcp::socket::shutdown_send, ec);
    });
  }
};

void ViewServer::Impl::accept() {
  acceptor.async_accept(ioc, [this](beast::error_code ec, tcp::socket socket) {
    if (!acceptor.is_open() || ec == net::error::operation_aborted) return;  // shutting down
    if (ec) {
      // Out of file descriptors, say: a moment later there may be some. Never stop accepting.
      if (Clock::now() - lastAcceptWarning > std::chrono::seconds(5)) {
        spdlog::warn("view: cannot accept a connection ({}); retrying", ec.message());
        lastAcceptWarning = Clock::now();
      }
      acceptRetry.expires_after(std::chrono::milliseconds(50));
      acceptRetry.async_wait([this](beast::error_code e) {
        if (!e) accept();
      });
      return;
    }
    std::make_shared<HttpConnection>(*this, std::move(socket))->start();
    accept();
  });
}

void ViewServer::Impl::shutdown() {
  beast::error_code ec;
  acceptor.close(ec);
  acceptRetry.cancel();
  if (client) client->close();
  client.reset();
  ioc.stop();
}

ViewServer::ViewServer(ViewSession& session, const ViewServerOptions& opts)
    : impl_(std::make_unique<Impl>(session, opts)) {
  beast::error_code ec;
  auto addr = net::ip::make_address(opts.host, ec);
  if (ec) throw std::runtime_error("view: '" + opts.host + "' is not an IP address");
  tcp::endpoint ep(addr, static_cast<unsigned short>(opts.port));
  impl_->acceptor.open(ep.protocol(), ec);
  if (!ec) impl_->acceptor.set_option(net::socket_base::reuse_address(true), ec);
  if (!ec) impl_->acceptor.bind(ep, ec);
  if (!ec) impl_->acceptor.listen(net::socket_base::max_listen_connections, ec);
  if (ec) throw std::runtime_error("view: cannot listen on " + opts.host + ":" + std::to_string(opts.port) + ": " + ec.message());
}

ViewServer::~ViewServer() = default;

int ViewServer::port() const { return impl_->acceptor.local_endpoint().port(); }

void ViewServer::run() {
  Impl& s = *impl_;
  s.signals.async_wait([&s](beast::error_code ec, int sig) {
    if (ec) return;
    spdlog::info("view: {} received, stopping", sig == SIGINT ? "SIGINT" : "SIGTERM");
    s.shutdown();
  });
  s.session.start([&s](ViewFrame f) {
    // From the render thread: hand the frame to the I/O thread, which owns the socket.
    net::post(s.ioc, [&s, f = std::move(f)]() mutable {
      if (!s.client) return;
      s.client->send(std::move(f.meta), false);
      if (!f.jpeg.empty()) s.client->send(std::move(f.jpeg), true);
    });
  });
  s.accept();
  s.ioc.run();
  s.session.stop();
}

void ViewServer::stop() {
  net::post(impl_->ioc, [this] { impl_->shutdown(); });
}

}  // namespace envgi
