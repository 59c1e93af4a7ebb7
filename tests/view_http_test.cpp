// prtr view's HTTP layer: the request head parser (every prefix of a request is incomplete,
// limits give 414/431, malformed heads 400, body framing by RFC 9112 Sec. 6.3), and the server
// over loopback with a handler that echoes the target: pipelined requests answered in the
// order sent, half-closed requests answered in full, bodies drained, HEAD without a body.
#include "http_request.h"  // viewer/src: the HTTP layer is private to the viewer
#include "http_server.h"

#include <gtest/gtest.h>

#include <arpa/inet.h>
#include <netinet/in.h>
#include <poll.h>
#include <sys/socket.h>
#include <unistd.h>

#include <chrono>
#include <memory>
#include <string>
#include <thread>
#include <vector>

namespace {

using viewer::detail::body_framing;
using viewer::detail::BodyFraming;
using viewer::detail::HeadParse;
using viewer::detail::HttpHead;
using viewer::detail::HttpLimits;
using viewer::detail::HttpResponse;
using viewer::detail::HttpServer;
using viewer::detail::HttpServerOptions;
using viewer::detail::parse_request_head;
using State = HeadParse::State;

HeadParse parse(const std::string& text, const HttpLimits& limits = {}) {
  return parse_request_head(text, limits);
}

TEST(HttpRequestHead, ParsesRequestLineAndFields) {
  const std::string text =
      "GET /frame?w=32 HTTP/1.1\r\nHost: 127.0.0.1:8080\r\nX-Mixed-Case:  a b \t\r\n\r\n";
  const HeadParse p = parse(text + "GET /next HTTP/1.1\r\n");
  ASSERT_EQ(p.state, State::complete) << p.reason;
  EXPECT_EQ(p.length, text.size());  // the pipelined request after it is left alone
  EXPECT_EQ(p.head.method, "GET");
  EXPECT_EQ(p.head.target, "/frame?w=32");
  EXPECT_EQ(p.head.minor_version, 1);
  ASSERT_NE(p.head.field("host"), nullptr);
  EXPECT_EQ(*p.head.field("host"), "127.0.0.1:8080");
  ASSERT_NE(p.head.field("x-mixed-case"), nullptr);
  EXPECT_EQ(*p.head.field("x-mixed-case"), "a b");
}

TEST(HttpRequestHead, EveryPrefixIsIncomplete) {
  for (const std::string text : {"GET / HTTP/1.1\r\nHost: h:1\r\nAccept: */*\r\n\r\n",
                                 "\r\nHEAD /a HTTP/1.0\nHost: h:1\n\n"}) {
    for (std::size_t n = 0; n < text.size(); ++n)
      EXPECT_EQ(parse(text.substr(0, n)).state, State::need_more) << n << " of " << text;
    const HeadParse p = parse(text);
    ASSERT_EQ(p.state, State::complete) << text;
    EXPECT_EQ(p.length, text.size());
  }
}

TEST(HttpRequestHead, LimitsRefuseAsSoonAsPassed) {
  HttpLimits limits;
  limits.max_target = 100;
  limits.max_header_bytes = 200;
  limits.max_header_fields = 3;
  const std::string long_target = "/" + std::string(100, 'a');
  EXPECT_EQ(parse("GET " + long_target + " HTTP/1.1\r\n\r\n", limits).status, 414);
  EXPECT_EQ(parse("GET " + long_target.substr(0, 100) + " HTTP/1.1\r\n\r\n", limits).state,
            State::complete);
  // Unfinished: a target still arriving past the limit, 1 MB of it.
  EXPECT_EQ(parse("GET /" + std::string(1 << 20, 'a'), limits).status, 414);
  EXPECT_EQ(parse(std::string(1 << 20, 'a'), limits).status, 400);  // no method, no target
  // The line's bound holds whole or cut: a 60-byte method beside a 100-byte target.
  const std::string long_method = std::string(60, 'M') + " " + long_target.substr(0, 100);
  EXPECT_EQ(parse(long_method + " HTTP/1.1\r\n\r\n", limits).status, 400);
  EXPECT_EQ(parse(long_method + " HTTP/1", limits).status, 400);
  EXPECT_EQ(parse(std::string(50, 'M') + " /a HTTP/1.1\r\n\r\n", limits).state, State::complete);
  const std::string line = "GET / HTTP/1.1\r\n";
  EXPECT_EQ(parse(line + "X: " + std::string(1 << 20, 'b'), limits).status, 431);
  EXPECT_EQ(parse(line + "X: " + std::string(196, 'b') + "\r\n\r\n", limits).status, 431);
  EXPECT_EQ(parse(line + "X: " + std::string(150, 'b') + "\r\n\r\n", limits).state,
            State::complete);
  limits.max_field_line = 120;  // one line: its bytes through the LF
  EXPECT_EQ(parse(line + "X: " + std::string(115, 'b') + "\r\n\r\n", limits).state,
            State::complete);
  EXPECT_EQ(parse(line + "X: " + std::string(116, 'b') + "\r\n\r\n", limits).status, 431);
  EXPECT_EQ(parse(line + "X: " + std::string(118, 'b'), limits).status, 431);
  EXPECT_EQ(parse(line + "A: 1\r\nB: 2\r\nC: 3\r\n\r\n", limits).state, State::complete);
  EXPECT_EQ(parse(line + "A: 1\r\nB: 2\r\nC: 3\r\nD: 4\r\n\r\n", limits).status, 431);
}

TEST(HttpRequestHead, AbsoluteAndAsteriskForms) {
  // RFC 9112 Sec. 3.2.2: the authority of an absolute-form target replaces the Host field.
  const HeadParse p = parse("GET http://LocalHost:8080/frame?w=1 HTTP/1.1\r\nHost: evil:1\r\n\r\n");
  ASSERT_EQ(p.state, State::complete) << p.reason;
  EXPECT_EQ(p.head.target, "/frame?w=1");
  ASSERT_NE(p.head.field("host"), nullptr);
  EXPECT_EQ(*p.head.field("host"), "LocalHost:8080");
  EXPECT_EQ(p.head.fields.size(), 1u);
  EXPECT_EQ(parse("GET HTTP://h:1 HTTP/1.1\r\n\r\n").head.target, "/");
  EXPECT_EQ(parse("GET http://h:1?x HTTP/1.1\r\n\r\n").head.target, "/?x");
  EXPECT_EQ(parse("OPTIONS * HTTP/1.1\r\nHost: h:1\r\n\r\n").head.target, "*");
  for (const char* bad : {"GET * HTTP/1.1\r\n\r\n", "GET http:// HTTP/1.1\r\n\r\n",
                          "GET http:///x HTTP/1.1\r\n\r\n", "GET https://h/ HTTP/1.1\r\n\r\n",
                          "GET http://u@h/ HTTP/1.1\r\n\r\n", "GET h:1/x HTTP/1.1\r\n\r\n"})
    EXPECT_EQ(parse(bad).status, 400) << bad;
}

TEST(HttpRequestHead, MalformedHeadsAreRefused) {
  const std::vector<std::pair<std::string, int>> cases = {
      {"GARBAGE\r\n\r\n", 400},
      {"GET  / HTTP/1.1\r\n\r\n", 400},
      {"GET / HTTP/1.1 x\r\n\r\n", 400},
      {"G(T / HTTP/1.1\r\n\r\n", 400},
      {"GET ftp://evil/ HTTP/1.1\r\n\r\n", 400},
      {"GET * HTTP/1.1\r\n\r\n", 400},
      {"GET /\x01 HTTP/1.1\r\n\r\n", 400},
      {"GET / HTTP/2.0\r\n\r\n", 505},
      {"GET / HTTP/0.9\r\n\r\n", 400},
      {"GET / http/1.1\r\n\r\n", 400},
      {"GET / HTTP/1.1\r\nHost : x\r\n\r\n", 400},
      {"GET / HTTP/1.1\r\nA: 1\r\n folded\r\n\r\n", 400},
      {"GET / HTTP/1.1\r\nA: 1\r2\r\n\r\n", 400},
      {"GET / HTTP/1.1\r\nA: \x7f\r\n\r\n", 400},
      {std::string("GET / HTTP/1.1\r\nA: 1\0\r\n\r\n", 25), 400},
      {"GET / HTTP/1.1\r\n: empty name\r\n\r\n", 400},
      {"GET / HTTP/1.1\r\nHost: a:1\r\nHost: b:1\r\n\r\n", 400},
      {std::string(17 * 2, '\r') + "\n", 400},
  };
  for (const auto& [text, status] : cases) {
    const HeadParse p = parse(text);
    EXPECT_EQ(p.state, State::refused) << text;
    EXPECT_EQ(p.status, status) << text;
    EXPECT_EQ(p.reason.find('\n'), std::string::npos) << text;
  }
  // Sixteen empty lines before a request are skipped; the limit is on more.
  std::string empties;
  for (int i = 0; i < 16; ++i) empties += "\r\n";
  EXPECT_EQ(parse(empties + "GET / HTTP/1.1\r\n\r\n").state, State::complete);
  EXPECT_EQ(parse(empties + "\r\nGET / HTTP/1.1\r\n\r\n").status, 400);
}

HttpHead head_with(std::vector<std::pair<std::string, std::string>> fields, int minor = 1) {
  HttpHead head;
  head.method = "GET";
  head.target = "/";
  head.minor_version = minor;
  head.fields = std::move(fields);
  return head;
}

TEST(HttpRequestHead, BodyFramingFollowsRfc9112) {
  const HttpLimits limits;
  using Kind = BodyFraming::Kind;
  EXPECT_EQ(body_framing(head_with({}), limits).kind, Kind::none);
  EXPECT_EQ(body_framing(head_with({{"content-length", "0"}}), limits).kind, Kind::none);
  const BodyFraming five = body_framing(head_with({{"content-length", "5"}}), limits);
  EXPECT_EQ(five.kind, Kind::length);
  EXPECT_EQ(five.length, 5u);
  EXPECT_EQ(body_framing(head_with({{"content-length", "7, 7"}}), limits).length, 7u);
  EXPECT_EQ(
      body_framing(head_with({{"content-length", "7"}, {"content-length", "7"}}), limits).length,
      7u);
  for (const char* bad : {"7, 8", "-1", "+5", "", "5x", "0x10", "99999999999999999999"})
    EXPECT_EQ(body_framing(head_with({{"content-length", bad}}), limits).status, 400) << bad;
  EXPECT_EQ(
      body_framing(head_with({{"content-length", "1"}, {"content-length", "2"}}), limits).status,
      400);
  EXPECT_EQ(body_framing(head_with({{"transfer-encoding", "chunked"}}), limits).kind,
            Kind::unframed);
  EXPECT_EQ(
      body_framing(head_with({{"transfer-encoding", "chunked"}, {"content-length", "3"}}), limits)
          .status,
      400);
  EXPECT_EQ(
      body_framing(head_with({{"content-length", std::to_string(limits.max_body + 1)}}), limits)
          .status,
      413);
}

TEST(HttpRequestHead, KeepAliveByVersionAndConnection) {
  EXPECT_TRUE(head_with({}).keep_alive());
  EXPECT_FALSE(head_with({{"connection", "close"}}).keep_alive());
  EXPECT_FALSE(head_with({{"connection", "keep-alive, Close"}}).keep_alive());
  EXPECT_FALSE(head_with({}, 0).keep_alive());
  EXPECT_TRUE(head_with({{"connection", "Keep-Alive"}}, 0).keep_alive());
  EXPECT_FALSE(head_with({{"connection", "closed"}}).has_token("connection", "close"));
}

// --- The server over loopback -------------------------------------------------------------

// A server on 127.0.0.1, any port, answering every request with its method and target.
class EchoServer {
 public:
  explicit EchoServer(HttpServerOptions options = {})
      : server_(with_loopback(options),
                [](const HttpHead& req) {
                  HttpResponse res;
                  res.content_type = "text/plain";
                  res.body = req.method + " " + req.target;
                  return res;
                }),
        thread_([this] { server_.serve(); }) {}
  ~EchoServer() {
    server_.stop();
    thread_.join();
  }
  int port() const { return server_.port(); }

 private:
  static HttpServerOptions with_loopback(HttpServerOptions options) {
    options.host = "127.0.0.1";
    options.port = 0;
    return options;
  }
  HttpServer server_;
  std::thread thread_;
};

int connect_to(int port) {
  const int fd = ::socket(AF_INET, SOCK_STREAM, 0);
  sockaddr_in address{};
  address.sin_family = AF_INET;
  address.sin_port = htons(std::uint16_t(port));
  address.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  EXPECT_EQ(::connect(fd, reinterpret_cast<sockaddr*>(&address), sizeof address), 0);
  return fd;
}

void send_all(int fd, const std::string& bytes) {
  std::size_t sent = 0;
  while (sent < bytes.size()) {
    const ssize_t n = ::send(fd, bytes.data() + sent, bytes.size() - sent, MSG_NOSIGNAL);
    if (n <= 0) return;  // the server closed; the reply tells
    sent += std::size_t(n);
  }
}

// Everything the server sends until it closes (or 10 s pass: the test then fails on content).
std::string read_to_end(int fd) {
  std::string out;
  char chunk[65536];
  for (;;) {
    pollfd p{fd, POLLIN, 0};
    if (::poll(&p, 1, 10000) <= 0) return out + "<timeout>";
    const ssize_t n = ::recv(fd, chunk, sizeof chunk, 0);
    if (n <= 0) return out;
    out.append(chunk, std::size_t(n));
  }
}

struct Reply {
  int status = 0;
  std::string head;
  std::string body;
};

// Splits a byte stream of answers by their Content-Length; `head_only` marks answers to HEAD.
std::vector<Reply> split_replies(const std::string& stream, const std::vector<bool>& head_only) {
  std::vector<Reply> replies;
  std::size_t pos = 0;
  for (std::size_t i = 0; pos < stream.size(); ++i) {
    const std::size_t end = stream.find("\r\n\r\n", pos);
    if (end == std::string::npos) break;
    Reply r;
    r.head = stream.substr(pos, end + 4 - pos);
    r.status = std::stoi(r.head.substr(9, 3));
    const std::size_t cl = r.head.find("Content-Length: ");
    const std::size_t length = cl == std::string::npos ? 0 : std::stoul(r.head.substr(cl + 16));
    pos = end + 4;
    if (i >= head_only.size() || !head_only[i]) {
      r.body = stream.substr(pos, length);
      pos += length;
    }
    replies.push_back(r);
  }
  return replies;
}

std::string get(const std::string& target, const std::string& extra = "") {
  return "GET " + target + " HTTP/1.1\r\nHost: 127.0.0.1\r\n" + extra + "\r\n";
}

TEST(HttpServer, AnswersPipelinedRequestsInOrder) {
  EchoServer server;
  const int fd = connect_to(server.port());
  std::string burst;
  for (int i = 0; i < 7; ++i) burst += get("/r" + std::to_string(i));
  burst += get("/last", "Connection: close\r\n");
  send_all(fd, burst);  // in one write: the requests arrive together
  const std::vector<Reply> replies = split_replies(read_to_end(fd), {});
  ::close(fd);
  ASSERT_EQ(replies.size(), 8u);
  for (int i = 0; i < 7; ++i) {
    EXPECT_EQ(replies[i].status, 200);
    EXPECT_EQ(replies[i].body, "GET /r" + std::to_string(i));
  }
  EXPECT_EQ(replies[7].body, "GET /last");
  EXPECT_NE(replies[7].head.find("Connection: close"), std::string::npos);
}

TEST(HttpServer, AnswersHalfClosedRequestsThenCloses) {
  EchoServer server;
  for (const std::string extra : {"", "Connection: close\r\n"}) {
    const int fd = connect_to(server.port());
    send_all(fd, get("/a", extra) + get("/b", extra));
    ::shutdown(fd, SHUT_WR);
    const std::vector<Reply> replies = split_replies(read_to_end(fd), {});
    ::close(fd);
    // With "Connection: close" the first answer is the last.
    ASSERT_EQ(replies.size(), extra.empty() ? 2u : 1u) << extra;
    EXPECT_EQ(replies[0].body, "GET /a");
    if (extra.empty()) {
      EXPECT_EQ(replies[1].body, "GET /b");
    }
  }
  // A request cut short by the half-close is not answered; the connection just closes.
  const int fd = connect_to(server.port());
  send_all(fd, "GET /a HTTP/1.1\r\nHost: 127.0.0.1\r\n");
  ::shutdown(fd, SHUT_WR);
  EXPECT_EQ(read_to_end(fd), "");
  ::close(fd);
}

TEST(HttpServer, DrainsBodiesAndAnswersHeadWithoutBody) {
  EchoServer server;
  const int fd = connect_to(server.port());
  send_all(fd, "POST /a HTTP/1.1\r\nHost: 127.0.0.1\r\nContent-Length: 11\r\n\r\nGET /x HTTP" +
                   std::string("HEAD /b HTTP/1.1\r\nHost: 127.0.0.1\r\n\r\n") +
                   get("/c", "Connection: close\r\n"));
  const std::vector<Reply> replies = split_replies(read_to_end(fd), {false, true, false});
  ::close(fd);
  ASSERT_EQ(replies.size(), 3u);
  EXPECT_EQ(replies[0].body, "POST /a");  // the body looked like a request; it was not one
  EXPECT_NE(replies[1].head.find("Content-Length: 7\r\n"), std::string::npos);  // "HEAD /b"
  EXPECT_EQ(replies[2].body, "GET /c");
}

TEST(HttpServer, RefusesOverlongHeadsWithAnAnswer) {
  EchoServer server;
  const std::vector<std::pair<std::string, int>> cases = {
      {"GET /" + std::string(1 << 20, 'a') + " HTTP/1.1\r\n\r\n", 414},
      {"GET / HTTP/1.1\r\nX: " + std::string(1 << 20, 'b') + "\r\n\r\n", 431},
      {"GET / HTTP/1.1\r\nContent-Length: 100000000\r\n\r\n", 413},
      {"GET / HTTP/1.1\r\nTransfer-Encoding: chunked\r\nContent-Length: 3\r\n\r\n", 400},
  };
  for (const auto& [request, status] : cases) {
    const int fd = connect_to(server.port());
    std::thread writer([&] {
      send_all(fd, request);
      ::shutdown(fd, SHUT_WR);
    });
    const std::string reply = read_to_end(fd);
    writer.join();
    ::close(fd);
    ASSERT_GE(reply.size(), 12u) << status;
    EXPECT_EQ(std::stoi(reply.substr(9, 3)), status);
    EXPECT_NE(reply.find("Connection: close"), std::string::npos);
  }
}

TEST(HttpServer, SlowClientDoesNotHoldOthers) {
  EchoServer server;
  const int slow = connect_to(server.port());
  send_all(slow, "GET /slow HTTP/1.1\r\n");
  const int fast = connect_to(server.port());
  send_all(fast, get("/1") + get("/2", "Connection: close\r\n"));
  const std::vector<Reply> replies = split_replies(read_to_end(fast), {});
  ::close(fast);
  ASSERT_EQ(replies.size(), 2u);
  EXPECT_EQ(replies[1].body, "GET /2");
  // The slow one, still unanswered, finishes its head and is answered.
  pollfd p{slow, POLLIN, 0};
  EXPECT_EQ(::poll(&p, 1, 0), 0);
  send_all(slow, "Host: 127.0.0.1\r\nConnection: close\r\n\r\n");
  const std::vector<Reply> late = split_replies(read_to_end(slow), {});
  ::close(slow);
  ASSERT_EQ(late.size(), 1u);
  EXPECT_EQ(late[0].body, "GET /slow");
}

TEST(HttpServer, IncompleteHeadTimesOutWith408) {
  HttpServerOptions options;
  options.head_timeout = std::chrono::milliseconds(300);
  options.idle_timeout = std::chrono::milliseconds(600);
  EchoServer server(options);
  const int fd = connect_to(server.port());
  send_all(fd, "GET / HTTP/1.1\r\n");
  const std::string reply = read_to_end(fd);
  ::close(fd);
  EXPECT_EQ(reply.substr(0, 12), "HTTP/1.1 408");
  // An empty line after a request is not the start of another: the connection is idle and
  // closes quietly after the idle timeout.
  const int idle = connect_to(server.port());
  send_all(idle, get("/a") + "\r\n");
  const std::vector<Reply> replies = split_replies(read_to_end(idle), {});
  ::close(idle);
  ASSERT_EQ(replies.size(), 1u);
  EXPECT_EQ(replies[0].body, "GET /a");
}

TEST(HttpServer, StopClosesIdleConnections) {
  HttpServerOptions options;
  options.idle_timeout = std::chrono::minutes(5);  // so that only the stop can close it
  auto server = std::make_unique<EchoServer>(options);
  const int fd = connect_to(server->port());
  send_all(fd, get("/a"));
  std::string first;
  while (first.find("GET /a") == std::string::npos) {
    char chunk[256];
    const ssize_t n = ::recv(fd, chunk, sizeof chunk, 0);
    ASSERT_GT(n, 0);
    first.append(chunk, std::size_t(n));
  }
  std::thread stopper([&] { server.reset(); });
  EXPECT_EQ(read_to_end(fd), "");  // closed, not "<timeout>"
  stopper.join();
  ::close(fd);
}

}  // namespace
