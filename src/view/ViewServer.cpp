#include "view/ViewServer.h"

#include <spdlog/spdlog.h>

#include <boost/asio/signal_set.hpp>
#include <boost/asio/strand.hpp>
#include <boost/beast/core.hpp>
#include <boost/beast/http.hpp>
#include <boost/beast/websocket.hpp>
#include <deque>
#include <nlohmann/json.hpp>

#include "view/ViewerPage.h"

namespace envgi {

namespace beast = boost::beast;
namespace http = beast::http;
namespace websocket = beast::websocket;
namespace net = boost::asio;
using tcp = net::ip::tcp;

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

}  // namespace

class WsClient;

struct ViewServer::Impl {
  ViewSession& session;
  ViewServerOptions opts;
  net::io_context ioc{1};
  tcp::acceptor acceptor{ioc};
  net::signal_set signals{ioc, SIGINT, SIGTERM};
  std::shared_ptr<WsClient> client;  // the one connected page (I/O thread only)

  Impl(ViewSession& s, const ViewServerOptions& o) : session(s), opts(o) {}
  void accept();
  void shutdown();
};

// One page's WebSocket: reads its messages, writes frames and replies through a queue (one
// write in flight, as Beast requires).
class WsClient : public std::enable_shared_from_this<WsClient> {
 public:
  WsClient(ViewServer::Impl& server, tcp::socket socket) : server_(server), ws_(std::move(socket)) {}

  void start(http::request<http::string_body> req) {
    ws_.set_option(websocket::stream_base::timeout::suggested(beast::role_type::server));
    ws_.async_accept(req, [self = shared_from_this()](beast::error_code ec) { self->onAccept(ec); });
  }

  void send(std::string text, bool binary) {
    queue_.push_back({std::move(text), binary});
    if (queue_.size() == 1) writeNext();
  }

  void close() {
    closed_ = true;
    beast::error_code ec;
    beast::get_lowest_layer(ws_).socket().close(ec);
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

  void onAccept(beast::error_code ec) {
    if (ec) return;
    if (server_.client) {
      spdlog::warn("view: a second client was refused (one page at a time)");
      auto self = shared_from_this();
      send(nlohmann::json{{"type", "error"}, {"message", "another page is already connected"}}.dump(), false);
      ws_.async_close(websocket::close_code::try_again_later, [self](beast::error_code) {});
      return;
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
    std::string msg = beast::buffers_to_string(buffer_.data());
    buffer_.consume(buffer_.size());
    try {
      std::string reply = server_.session.handle(msg);
      if (!reply.empty()) send(reply, false);
    } catch (const std::exception& e) {
      spdlog::warn("view: {}", e.what());
      send(nlohmann::json{{"type", "error"}, {"message", e.what()}}.dump(), false);
    }
    read();
  }

  void writeNext() {
    ws_.binary(queue_.front().binary);
    ws_.async_write(net::buffer(queue_.front().data), [self = shared_from_this()](beast::error_code ec, size_t) {
      self->queue_.pop_front();
      if (ec) return;  // the read side notices and logs
      if (!self->queue_.empty()) self->writeNext();
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
    if (!server_.opts.token.empty() && queryValue(target, "token") != server_.opts.token)
      return reply(http::status::forbidden, "text/plain", "envgi view: this server needs its token (?token=...)\n");
    if (path == "/ws" && websocket::is_upgrade(req_)) {
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
    if (ec) return;  // closed: shutting down
    std::make_shared<HttpConnection>(*this, std::move(socket))->start();
    accept();
  });
}

void ViewServer::Impl::shutdown() {
  beast::error_code ec;
  acceptor.close(ec);
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
