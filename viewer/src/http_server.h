// viewer/src/http_server.h (private): prtr view's HTTP/1.1 server, a thread per connection
// (viewer/src/connection_threads.h) reading requests with viewer/src/http_request.h.
//
// It replaces cpp-httplib 0.11, which could not be fixed from outside for two defects:
// - Pipelining (RFC 9112 Sec. 9.3.2): httplib reads a request through a SocketStream that it
//   constructs per request inside its keep-alive loop, with a 4 KiB read-ahead buffer. The
//   requests a client wrote after the first arrive in the same read and die with that stream;
//   the loop then waits on the socket for bytes it has already consumed, and the connection
//   times out with one answer.
// - Half-close: before writing an answer httplib checks SocketStream::is_writable(), which
//   calls is_socket_alive(): a one-byte MSG_PEEK that reads end of stream (0) as a dead peer.
//   A client that shut down its sending side after its request (`nc -N`, some proxies) is
//   alive and waiting, but gets no answer.
// Both sit in non-virtual code inside the shared library, below any hook httplib offers.
//
// Here a connection keeps one buffer for its whole life: what follows a request's head and
// body stays there and is the next request, answered in order. End of stream from the client
// only means no further requests: those already received are answered, then the connection
// closes. Bounds: a read or write waits at most `io_timeout` for the peer, a request's head
// must arrive whole within `head_timeout` (else 408), an idle keep-alive connection closes
// after `idle_timeout`, and the limits of HttpLimits give 414, 431 and 413. On stop, idle
// connections close at once and answers in progress get `grace` before every open socket is
// shut down.
#pragma once

#include "connection_threads.h"
#include "http_request.h"

#include <atomic>
#include <chrono>
#include <functional>
#include <mutex>
#include <set>
#include <string>
#include <utility>
#include <vector>

namespace viewer::detail {

struct HttpResponse {
  int status = 200;
  std::string content_type;  // with a body; empty for none (204)
  std::string body;
  std::vector<std::pair<std::string, std::string>> headers;  // beyond the framing ones
};

// The answer for a one-line reason (a text/plain body ending in a newline).
HttpResponse text_response(int status, const std::string& text);

struct HttpServerOptions {
  std::string host = "127.0.0.1";
  int port = 0;  // 0: any free port
  std::size_t max_connections = 128;
  std::chrono::milliseconds io_timeout{5000};
  std::chrono::milliseconds idle_timeout{5000};
  std::chrono::milliseconds head_timeout{10000};
  std::chrono::milliseconds grace{500};
  HttpLimits limits;
};

// Called on a connection's thread for every complete request (GET, HEAD or any other method);
// for HEAD the server sends the headers of the answer without its body. An exception becomes
// a 500 naming it.
using HttpHandler = std::function<HttpResponse(const HttpHead&)>;

class HttpServer {
 public:
  // Binds and listens (SO_REUSEADDR, not SO_REUSEPORT: a second server on the port fails).
  // Throws std::runtime_error naming the address when it cannot.
  HttpServer(const HttpServerOptions& options, HttpHandler handler);
  ~HttpServer();
  HttpServer(const HttpServer&) = delete;
  HttpServer& operator=(const HttpServer&) = delete;

  int port() const { return port_; }
  // Accepts and serves until stop(), then waits for the connections (see above).
  void serve();
  // From any thread, before or during serve().
  void stop();

 private:
  class Connection;
  void serve_connection(int fd);
  void forget(int fd);  // closes it
  void cut_off_connections();

  const HttpServerOptions options_;
  const HttpHandler handler_;
  int listen_fd_ = -1;
  int port_ = 0;
  int stop_pipe_[2] = {-1, -1};  // readable once stopping: wakes every poll
  std::atomic<bool> stopping_{false};
  std::mutex open_mutex_;
  std::set<int> open_;         // connected sockets not yet closed
  ConnectionThreads threads_;  // last: joined before the members above go
};

}  // namespace viewer::detail
