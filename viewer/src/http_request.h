// viewer/src/http_request.h (private): the head of one HTTP/1.1 request (request line and
// header fields, RFC 9112 Secs. 2-5) parsed from the bytes a connection has received so far.
//
// The parser does no I/O and keeps no state: it is called again on the grown buffer until the
// head is complete, and reports how many bytes the head took, so the bytes after it (a body,
// or the next pipelined request) stay in the caller's buffer. Every limit is checked on the
// bytes seen so far, so a 1 MB target or header is refused as soon as the limit is passed,
// not once it has all arrived.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

namespace viewer::detail {

struct HttpLimits {
  std::size_t max_target = 8192;         // request target bytes; past it 414
  std::size_t max_field_line = 8192;     // one header line; 431
  std::size_t max_header_bytes = 65536;  // header section bytes after the request line; 431
  std::size_t max_header_fields = 100;   // 431
  std::uint64_t max_body = 65536;        // Content-Length drained; past it 413
};

struct HttpHead {
  std::string method;
  std::string target;     // as sent (origin-form: starts with '/')
  int minor_version = 1;  // HTTP/1.minor_version
  std::vector<std::pair<std::string, std::string>> fields;  // names lower-cased, values trimmed

  // The value of the first field named `name` (lower case), or nullptr.
  const std::string* field(std::string_view name) const;
  // Whether the comma-separated list of every field named `name` holds `token`
  // (case-insensitive), e.g. has_token("connection", "close").
  bool has_token(std::string_view name, std::string_view token) const;
  // Whether the connection stays open after the answer (HTTP/1.1 unless "Connection: close",
  // HTTP/1.0 only with "Connection: keep-alive").
  bool keep_alive() const;
};

struct HeadParse {
  enum class State { need_more, complete, refused };
  State state = State::need_more;
  std::size_t length = 0;  // complete: the bytes the head took (through its empty line)
  HttpHead head;           // complete
  int status = 0;          // refused: 400, 414, 431, 501 or 505
  std::string reason;      // refused: one line for the answer's body
};

// `buffer` holds what the connection received since the previous request's end. Leading empty
// lines are skipped (RFC 9112 Sec. 2.2). Lines end in CRLF or a bare LF; a bare CR, a control
// character, whitespace before a field's colon, a folded line, a second Host, a target that is
// neither a path nor http://authority[/path] (nor "*" for OPTIONS) is refused (400), as is a
// version other than HTTP/1.x (505 for HTTP/2 and later in the request line).
HeadParse parse_request_head(std::string_view buffer, const HttpLimits& limits);

// How the body after a complete head is framed (RFC 9112 Sec. 6.3, requests).
struct BodyFraming {
  enum class Kind { none, length, unframed, refused };
  Kind kind = Kind::none;
  std::uint64_t length = 0;  // Kind::length
  int status = 0;            // Kind::refused: 400 (bad Content-Length, or it beside
                             // Transfer-Encoding) or 413 (longer than limits.max_body)
  std::string reason;
};
// Kind::unframed: a Transfer-Encoding, whose end the server does not look for (it takes no
// request bodies): the request is answered and the connection closed.
BodyFraming body_framing(const HttpHead& head, const HttpLimits& limits);

// The reason phrase of the statuses the viewer sends ("Unknown" for others).
const char* status_text(int status);

}  // namespace viewer::detail
