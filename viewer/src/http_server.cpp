#include "http_server.h"

#include <fcntl.h>
#include <netdb.h>
#include <netinet/in.h>
#include <netinet/tcp.h>
#include <poll.h>
#include <sys/socket.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstring>
#include <exception>
#include <stdexcept>
#include <thread>

namespace viewer::detail {
namespace http_server_io {

using Clock = std::chrono::steady_clock;

// Milliseconds left until `deadline`, for poll(2): 0 once it has passed.
int millis_until(Clock::time_point deadline) {
  const auto left =
      std::chrono::duration_cast<std::chrono::milliseconds>(deadline - Clock::now()).count();
  return left <= 0 ? 0 : int(std::min<long long>(left, 1 << 30));
}

std::runtime_error cannot_listen(const std::string& host, int port) {
  return std::runtime_error("prtr view: cannot listen on " + host + ":" + std::to_string(port) +
                            " (in use, or not an address of this machine); choose another "
                            "--port or --host");
}

// A socket bound to one of `host`'s addresses and listening; -1 when none would bind.
int listen_on(const std::string& host, int port) {
  addrinfo hints{};
  hints.ai_family = AF_UNSPEC;
  hints.ai_socktype = SOCK_STREAM;
  hints.ai_flags = AI_PASSIVE | AI_NUMERICSERV;
  addrinfo* found = nullptr;
  if (::getaddrinfo(host.c_str(), std::to_string(port).c_str(), &hints, &found) != 0) return -1;
  int fd = -1;
  for (const addrinfo* a = found; a != nullptr && fd < 0; a = a->ai_next) {
    fd = ::socket(a->ai_family, a->ai_socktype | SOCK_CLOEXEC, a->ai_protocol);
    if (fd < 0) continue;
    // SO_REUSEADDR only (a restart need not wait out TIME_WAIT); SO_REUSEPORT would let a
    // second viewer bind the same port and take half the requests.
    const int yes = 1;
    ::setsockopt(fd, SOL_SOCKET, SO_REUSEADDR, &yes, sizeof yes);
    if (::bind(fd, a->ai_addr, a->ai_addrlen) != 0 || ::listen(fd, SOMAXCONN) != 0) {
      ::close(fd);
      fd = -1;
    }
  }
  ::freeaddrinfo(found);
  return fd;
}

int bound_port(int fd) {
  sockaddr_storage address{};
  socklen_t size = sizeof address;
  if (::getsockname(fd, reinterpret_cast<sockaddr*>(&address), &size) != 0) return -1;
  if (address.ss_family == AF_INET)
    return ntohs(reinterpret_cast<const sockaddr_in*>(&address)->sin_port);
  if (address.ss_family == AF_INET6)
    return ntohs(reinterpret_cast<const sockaddr_in6*>(&address)->sin6_port);
  return -1;
}

std::string serialize(const HttpResponse& response, bool head_only, bool closing) {
  std::string out = "HTTP/1.1 ";
  out += std::to_string(response.status);
  out += ' ';
  out += status_text(response.status);
  out += "\r\n";
  // RFC 9110 Sec. 8.6: no Content-Length in a 204.
  const bool has_body = response.status != 204;
  if (has_body) {
    if (!response.content_type.empty()) {
      out += "Content-Type: ";
      out += response.content_type;
      out += "\r\n";
    }
    out += "Content-Length: ";
    out += std::to_string(response.body.size());
    out += "\r\n";
  }
  for (const auto& [name, value] : response.headers) {
    out += name;
    out += ": ";
    out += value;
    out += "\r\n";
  }
  if (closing) out += "Connection: close\r\n";
  out += "\r\n";
  if (has_body && !head_only) out += response.body;
  return out;
}

}  // namespace http_server_io

namespace hio = http_server_io;

HttpResponse text_response(int status, const std::string& text) {
  HttpResponse response;
  response.status = status;
  response.content_type = "text/plain";
  response.body = text;
  response.body += '\n';
  return response;
}

// One accepted socket and the bytes received on it that no request has consumed yet.
class HttpServer::Connection {
 public:
  using Clock = hio::Clock;
  enum class Read { data, end, timeout, stopped, failed };

  Connection(const HttpServer& server, int fd) : server_(server), fd_(fd) {}

  std::string& buffer() { return in_; }
  bool peer_done() const { return peer_done_; }

  // Appends what arrives before `deadline`; `end` once the client has shut down its side.
  Read read_some(Clock::time_point deadline) {
    pollfd fds[2] = {{fd_, POLLIN, 0}, {server_.stop_pipe_[0], POLLIN, 0}};
    for (;;) {
      const int ready = ::poll(fds, 2, hio::millis_until(deadline));
      if (ready < 0 && errno == EINTR) continue;
      if (ready < 0) return Read::failed;
      if (ready == 0) return Read::timeout;
      if (fds[1].revents != 0) return Read::stopped;
      break;
    }
    char chunk[16384];
    const ssize_t n = ::recv(fd_, chunk, sizeof chunk, MSG_DONTWAIT);
    if (n > 0) {
      in_.append(chunk, std::size_t(n));
      return Read::data;
    }
    if (n == 0) {
      peer_done_ = true;
      return Read::end;
    }
    return (errno == EAGAIN || errno == EINTR) ? Read::data : Read::failed;
  }

  // The whole of `bytes`, each wait for the peer bounded by the I/O timeout. Not woken by a
  // stop: an answer in progress may finish within the grace period.
  bool write_all(const std::string& bytes) {
    std::size_t sent = 0;
    while (sent < bytes.size()) {
      pollfd fd{fd_, POLLOUT, 0};
      const int ready = ::poll(&fd, 1, int(server_.options_.io_timeout.count()));
      if (ready < 0 && errno == EINTR) continue;
      if (ready <= 0) return false;
      const ssize_t n =
          ::send(fd_, bytes.data() + sent, bytes.size() - sent, MSG_NOSIGNAL | MSG_DONTWAIT);
      if (n < 0 && (errno == EAGAIN || errno == EINTR)) continue;
      if (n <= 0) return false;
      sent += std::size_t(n);
    }
    return true;
  }

  // Closing with unread bytes in the kernel's buffer sends a reset, which can destroy the
  // answer before the client reads it (RFC 9112 Sec. 9.6). So: shut down our side, and read
  // and drop what still comes for a short while (the client's end, or up to 1 s).
  void close_gracefully() {
    if (peer_done_) return;
    ::shutdown(fd_, SHUT_WR);
    const auto deadline = Clock::now() + std::chrono::seconds(1);
    std::size_t dropped = 0;
    while (dropped < (std::size_t(4) << 20)) {
      in_.clear();
      if (read_some(deadline) != Read::data) return;
      dropped += in_.size();
    }
  }

 private:
  const HttpServer& server_;
  const int fd_;
  std::string in_;
  bool peer_done_ = false;
};

HttpServer::HttpServer(const HttpServerOptions& options, HttpHandler handler)
    : options_(options),
      handler_(std::move(handler)),
      threads_(options.max_connections, options.grace, [this] { cut_off_connections(); }) {
  listen_fd_ = hio::listen_on(options.host, options.port);
  if (listen_fd_ < 0) throw hio::cannot_listen(options.host, options.port);
  port_ = hio::bound_port(listen_fd_);
  if (::pipe2(stop_pipe_, O_CLOEXEC) != 0) {
    ::close(listen_fd_);
    throw std::runtime_error("prtr view: cannot create a pipe");
  }
}

HttpServer::~HttpServer() {
  stop();
  threads_.shutdown();
  ::close(listen_fd_);
  ::close(stop_pipe_[0]);
  ::close(stop_pipe_[1]);
}

void HttpServer::stop() {
  if (stopping_.exchange(true)) return;
  const char byte = 's';
  [[maybe_unused]] const ssize_t n = ::write(stop_pipe_[1], &byte, 1);
}

void HttpServer::serve() {
  pollfd fds[2] = {{listen_fd_, POLLIN, 0}, {stop_pipe_[0], POLLIN, 0}};
  while (!stopping_) {
    if (::poll(fds, 2, -1) < 0) {
      if (errno == EINTR) continue;
      break;
    }
    if (fds[1].revents != 0) break;
    const int fd = ::accept4(listen_fd_, nullptr, nullptr, SOCK_CLOEXEC);
    if (fd < 0) {
      // Out of descriptors or memory: let open connections finish before accepting again.
      if (errno == EMFILE || errno == ENFILE || errno == ENOBUFS || errno == ENOMEM)
        std::this_thread::sleep_for(std::chrono::milliseconds(50));
      continue;
    }
    // An answer goes out in one write, but the client's next request should not wait for a
    // delayed ACK either.
    const int yes = 1;
    ::setsockopt(fd, IPPROTO_TCP, TCP_NODELAY, &yes, sizeof yes);
    {
      std::lock_guard<std::mutex> lock(open_mutex_);
      open_.insert(fd);
    }
    threads_.enqueue([this, fd] {
      serve_connection(fd);
      forget(fd);
    });
  }
  threads_.shutdown();
}

void HttpServer::forget(int fd) {
  // Under the lock, so that cut_off_connections never shuts down a reused descriptor number.
  std::lock_guard<std::mutex> lock(open_mutex_);
  open_.erase(fd);
  ::close(fd);
}

void HttpServer::cut_off_connections() {
  std::lock_guard<std::mutex> lock(open_mutex_);
  for (const int fd : open_) ::shutdown(fd, SHUT_RDWR);
}

void HttpServer::serve_connection(int fd) {
  using Read = Connection::Read;
  using Clock = hio::Clock;
  Connection connection(*this, fd);
  std::string& in = connection.buffer();
  const HttpLimits& limits = options_.limits;
  const auto refuse = [&](int status, const std::string& reason) {
    connection.write_all(hio::serialize(text_response(status, reason), false, true));
    connection.close_gracefully();
  };
  for (;;) {
    // The head: parsed again when a line has ended or the buffer has doubled, so a head that
    // arrives a byte at a time costs linear time, and an overlong one is refused by 2x its limit.
    HeadParse parse = parse_request_head(in, limits);
    std::size_t next_check = std::max<std::size_t>(4096, 2 * in.size());
    Clock::time_point head_deadline = Clock::now() + options_.head_timeout;
    while (parse.state == HeadParse::State::need_more) {
      if (connection.peer_done() || stopping_) return;  // nothing (more) to answer
      // Empty lines between requests (RFC 9112 Sec. 2.2) do not start a request's head.
      const bool idle = in.find_first_not_of("\r\n") == std::string::npos;
      const auto deadline =
          std::min(idle ? Clock::now() + options_.idle_timeout : Clock::now() + options_.io_timeout,
                   idle ? Clock::time_point::max() : head_deadline);
      const std::size_t before = in.size();
      switch (connection.read_some(deadline)) {
        case Read::data:
          break;
        case Read::timeout:
          if (!idle) refuse(408, "the request's head did not arrive in time");
          return;
        default:
          return;  // end of a partial request, stopping, or an error
      }
      if (idle) head_deadline = Clock::now() + options_.head_timeout;
      if (in.find('\n', before) != std::string::npos || in.size() >= next_check) {
        parse = parse_request_head(in, limits);
        next_check = std::max(next_check, 2 * in.size());
      }
    }
    if (parse.state == HeadParse::State::refused) return refuse(parse.status, parse.reason);
    in.erase(0, parse.length);
    const HttpHead& head = parse.head;
    const BodyFraming framing = body_framing(head, limits);
    if (framing.kind == BodyFraming::Kind::refused) return refuse(framing.status, framing.reason);
    if (framing.kind == BodyFraming::Kind::length) {
      // No route takes a body: drain it so the next request starts where it should.
      std::uint64_t left = framing.length;
      for (;;) {
        const std::size_t take = std::size_t(std::min<std::uint64_t>(left, in.size()));
        in.erase(0, take);
        left -= take;
        if (left == 0) break;
        if (connection.read_some(Clock::now() + options_.io_timeout) != Read::data) return;
      }
    }
    HttpResponse response;
    try {
      response = handler_(head);
    } catch (const std::exception& e) {
      response = text_response(500, std::string("internal error: ") + e.what());
    } catch (...) {
      response = text_response(500, "internal error");
    }
    const bool keep =
        head.keep_alive() && framing.kind != BodyFraming::Kind::unframed && !stopping_;
    if (!connection.write_all(hio::serialize(response, head.method == "HEAD", !keep))) return;
    if (!keep) return connection.close_gracefully();
  }
}

}  // namespace viewer::detail
