// The viewer's HTTP + WebSocket server (Boost.Beast, one I/O thread): serves the page
// compiled into the binary at /, and one WebSocket client at /ws that steers the ViewSession
// and receives its frames; a newer page takes the session over. Binds 127.0.0.1 unless told
// otherwise; bound wider, every request must carry the token printed at start (?token=..., as
// Jupyter does). As Jupyter, it refuses a WebSocket whose Origin is not the page's own, and on
// loopback a Host that is not a loopback name (DNS rebinding). Only the scene it was started
// with, read-only: the page cannot name a file.
#pragma once

#include <memory>
#include <string>

#include "view/ViewSession.h"

namespace envgi {

struct ViewServerOptions {
  std::string host = "127.0.0.1";
  int port = 8000;      // 0: any free port
  std::string token;    // empty: none asked for
  // A page that answers no ping for this long is dropped, freeing the session for another.
  int idleSeconds = 10;
  // Replies and frames a page may leave unread before it is dropped (a page that sends and
  // never reads would otherwise grow the server's memory without bound).
  size_t maxQueued = 64;
  size_t maxMessageBytes = 64 * 1024;  // larger messages close the page's socket
};

class ViewServer {
 public:
  ViewServer(ViewSession& session, const ViewServerOptions& opts);
  ~ViewServer();
  // The port it listens on (the chosen one when asked for 0).
  int port() const;
  // Serves until stop(), SIGINT or SIGTERM; then closes the client and returns.
  void run();
  void stop();

  struct Impl;  // public so that the connection classes in the .cpp can name it

 private:
  std::unique_ptr<Impl> impl_;
};

}  // namespace envgi
