#include "http_request.h"

#include <algorithm>

namespace viewer::detail {
namespace http_request_parsing {

// RFC 9110 Sec. 5.6.2: the characters of a token (a method, a field name).
bool is_tchar(unsigned char c) {
  if (c >= '0' && c <= '9') return true;
  if ((c | 0x20) >= 'a' && (c | 0x20) <= 'z') return true;
  switch (c) {
    case '!':
    case '#':
    case '$':
    case '%':
    case '&':
    case '\'':
    case '*':
    case '+':
    case '-':
    case '.':
    case '^':
    case '_':
    case '`':
    case '|':
    case '~':
      return true;
    default:
      return false;
  }
}

bool is_token(std::string_view s) {
  return !s.empty() && std::all_of(s.begin(), s.end(), [](char c) { return is_tchar(c); });
}

// Field values: visible characters, space, tab and obs-text; never another control character.
bool is_field_value_char(unsigned char c) {
  return c == '\t' || c == ' ' || (c >= 0x21 && c != 0x7f);
}

char lower(char c) {
  return (c >= 'A' && c <= 'Z') ? char(c - 'A' + 'a') : c;
}

bool equal_ignoring_case(std::string_view a, std::string_view b) {
  if (a.size() != b.size()) return false;
  for (std::size_t i = 0; i < a.size(); ++i)
    if (lower(a[i]) != lower(b[i])) return false;
  return true;
}

std::string_view trim(std::string_view s) {
  while (!s.empty() && (s.front() == ' ' || s.front() == '\t')) s.remove_prefix(1);
  while (!s.empty() && (s.back() == ' ' || s.back() == '\t')) s.remove_suffix(1);
  return s;
}

// The line from `pos` to the next LF, without its LF and a CR just before it; false when no
// LF has arrived yet.
bool next_line(std::string_view buffer, std::size_t pos, std::string_view& line,
               std::size_t& next) {
  const std::size_t lf = buffer.find('\n', pos);
  if (lf == std::string_view::npos) return false;
  line = buffer.substr(pos, lf - pos);
  if (!line.empty() && line.back() == '\r') line.remove_suffix(1);
  next = lf + 1;
  return true;
}

HeadParse refused(int status, std::string reason) {
  HeadParse p;
  p.state = HeadParse::State::refused;
  p.status = status;
  p.reason = std::move(reason);
  return p;
}

// Longest method and version text, and the two spaces, beside the target.
constexpr std::size_t kRequestLineExtra = 64;
// Empty lines allowed before a request line (RFC 9112 Sec. 2.2 asks for at least one).
constexpr int kMaxLeadingEmptyLines = 16;

// A request line that has not ended yet but is already too long: 414 when the target is what
// is long, 400 otherwise.
HeadParse check_partial_request_line(std::string_view partial, const HttpLimits& limits) {
  if (partial.size() <= limits.max_target + kRequestLineExtra) return HeadParse{};
  const std::size_t space = partial.find(' ');
  if (space != std::string_view::npos && space <= kRequestLineExtra &&
      is_token(partial.substr(0, space))) {
    const std::string_view rest = partial.substr(space + 1);
    if (rest.substr(0, rest.find(' ')).size() > limits.max_target)
      return refused(414,
                     "request target longer than " + std::to_string(limits.max_target) + " bytes");
  }
  return refused(400, "request line longer than " +
                          std::to_string(limits.max_target + kRequestLineExtra) + " bytes");
}

// The origin-form of a target, and the authority of an absolute-form one (RFC 9112 Sec. 3.2);
// false for any other form.
bool origin_form(std::string_view method, std::string_view target, std::string& path,
                 std::string& authority) {
  if (target.front() == '/' || (target == "*" && method == "OPTIONS")) {
    path = std::string(target);
    return true;
  }
  constexpr std::string_view scheme = "http://";
  if (target.size() <= scheme.size() || !equal_ignoring_case(target.substr(0, 7), scheme))
    return false;
  const std::string_view rest = target.substr(scheme.size());
  const std::size_t end = std::min(rest.find_first_of("/?#"), rest.size());
  authority = std::string(rest.substr(0, end));
  if (authority.empty() || authority.find('@') != std::string::npos) return false;
  path = rest.substr(end).empty() || rest[end] != '/' ? "/" : "";
  path += rest.substr(end);
  return true;
}

// Fills method, target and version from a complete request line; a refusal when it is bad.
HeadParse parse_request_line(std::string_view line, const HttpLimits& limits, HttpHead& head,
                             std::string& authority) {
  // The same bound as while it arrives, so that the answer never depends on how it was cut.
  if (HeadParse bad = check_partial_request_line(line, limits);
      bad.state == HeadParse::State::refused)
    return bad;
  const std::size_t first = line.find(' ');
  const std::size_t second = first == std::string_view::npos ? first : line.find(' ', first + 1);
  if (second == std::string_view::npos || line.find(' ', second + 1) != std::string_view::npos)
    return refused(400, "malformed request line (expected METHOD TARGET HTTP/1.1)");
  const std::string_view method = line.substr(0, first);
  const std::string_view target = line.substr(first + 1, second - first - 1);
  const std::string_view version = line.substr(second + 1);
  if (!is_token(method)) return refused(400, "malformed method");
  if (target.size() > limits.max_target)
    return refused(414,
                   "request target longer than " + std::to_string(limits.max_target) + " bytes");
  if (target.empty() ||
      !std::all_of(target.begin(), target.end(), [](char c) { return c > 0x20 && c < 0x7f; }))
    return refused(400, "malformed request target");
  std::string path;
  if (!origin_form(method, target, path, authority))
    return refused(400, "request target must be a path starting with '/' or http://host/path");
  const bool shaped = version.size() == 8 && version.substr(0, 5) == "HTTP/" && version[6] == '.' &&
                      version[5] >= '0' && version[5] <= '9' && version[7] >= '0' &&
                      version[7] <= '9';
  if (!shaped) return refused(400, "malformed HTTP version");
  if (version[5] != '1')
    return refused(version[5] > '1' ? 505 : 400,
                   std::string(version) + " is not supported; use HTTP/1.1");
  head.method = std::string(method);
  head.target = std::move(path);
  head.minor_version = version[7] - '0';
  return HeadParse{};
}

// Adds one complete field line to `head`; a refusal when it is bad.
HeadParse parse_field_line(std::string_view line, const HttpLimits& limits, HttpHead& head) {
  if (line.front() == ' ' || line.front() == '\t')
    return refused(400, "folded header line (obsolete line folding is not accepted)");
  const std::size_t colon = line.find(':');
  if (colon == std::string_view::npos || !is_token(line.substr(0, colon)))
    return refused(400, "malformed header field");
  const std::string_view value = trim(line.substr(colon + 1));
  if (!std::all_of(value.begin(), value.end(),
                   [](char c) { return is_field_value_char(static_cast<unsigned char>(c)); }))
    return refused(400, "control character in a header field's value");
  if (head.fields.size() >= limits.max_header_fields)
    return refused(431, "more than " + std::to_string(limits.max_header_fields) + " header fields");
  std::string name(line.substr(0, colon));
  std::transform(name.begin(), name.end(), name.begin(), lower);
  if (name == "host" && head.field("host") != nullptr)
    return refused(400, "more than one Host header field");
  head.fields.emplace_back(std::move(name), std::string(value));
  return HeadParse{};
}

bool parse_length(std::string_view text, std::uint64_t& value) {
  if (text.empty() || text.size() > 18) return false;  // 18 digits cannot overflow
  value = 0;
  for (char c : text) {
    if (c < '0' || c > '9') return false;
    value = value * 10 + std::uint64_t(c - '0');
  }
  return true;
}

}  // namespace http_request_parsing

namespace hrp = http_request_parsing;

const std::string* HttpHead::field(std::string_view name) const {
  for (const auto& [n, v] : fields)
    if (n == name) return &v;
  return nullptr;
}

bool HttpHead::has_token(std::string_view name, std::string_view token) const {
  for (const auto& [n, v] : fields) {
    if (n != name) continue;
    std::string_view rest = v;
    while (!rest.empty()) {
      const std::size_t comma = rest.find(',');
      if (hrp::equal_ignoring_case(hrp::trim(rest.substr(0, comma)), token)) return true;
      if (comma == std::string_view::npos) break;
      rest.remove_prefix(comma + 1);
    }
  }
  return false;
}

bool HttpHead::keep_alive() const {
  if (has_token("connection", "close")) return false;
  return minor_version >= 1 || has_token("connection", "keep-alive");
}

HeadParse parse_request_head(std::string_view buffer, const HttpLimits& limits) {
  std::size_t pos = 0;
  for (int empty = 0;; ++empty) {
    if (pos < buffer.size() && buffer[pos] == '\n') {
      pos += 1;
    } else if (pos + 1 < buffer.size() && buffer[pos] == '\r' && buffer[pos + 1] == '\n') {
      pos += 2;
    } else if (pos + 1 == buffer.size() && buffer[pos] == '\r') {
      return HeadParse{};  // CR, its LF still to come
    } else {
      break;
    }
    if (empty == hrp::kMaxLeadingEmptyLines) return hrp::refused(400, "too many empty lines");
  }
  HeadParse result;
  std::string_view line;
  std::size_t next = 0;
  if (!hrp::next_line(buffer, pos, line, next))
    return hrp::check_partial_request_line(buffer.substr(pos), limits);
  std::string authority;
  if (HeadParse bad = hrp::parse_request_line(line, limits, result.head, authority);
      bad.state == HeadParse::State::refused)
    return bad;
  const std::size_t fields_start = next;
  for (pos = next;;) {
    const bool whole = hrp::next_line(buffer, pos, line, next);
    // The header section so far, counted through the line's LF or what has arrived of it.
    if ((whole ? next : buffer.size()) - fields_start > limits.max_header_bytes)
      return hrp::refused(
          431, "header section longer than " + std::to_string(limits.max_header_bytes) + " bytes");
    if ((whole ? next : buffer.size()) - pos > limits.max_field_line)
      return hrp::refused(
          431, "header line longer than " + std::to_string(limits.max_field_line) + " bytes");
    if (!whole) return HeadParse{};
    if (line.empty()) break;
    if (HeadParse bad = hrp::parse_field_line(line, limits, result.head);
        bad.state == HeadParse::State::refused)
      return bad;
    pos = next;
  }
  if (!authority.empty()) {
    std::vector<std::pair<std::string, std::string>>& fields = result.head.fields;
    fields.erase(std::remove_if(fields.begin(), fields.end(),
                                [](const auto& field) { return field.first == "host"; }),
                 fields.end());
    fields.emplace_back("host", std::move(authority));
  }
  result.state = HeadParse::State::complete;
  result.length = next;
  return result;
}

BodyFraming body_framing(const HttpHead& head, const HttpLimits& limits) {
  BodyFraming framing;
  const auto refuse = [&](int status, std::string reason) {
    framing.kind = BodyFraming::Kind::refused;
    framing.status = status;
    framing.reason = std::move(reason);
    return framing;
  };
  bool has_length = false;
  std::uint64_t length = 0;
  for (const auto& [name, value] : head.fields) {
    if (name != "content-length") continue;
    // A list of identical values counts as one (RFC 9110 Sec. 8.6); anything else is refused.
    std::string_view rest = value;
    for (;;) {
      const std::size_t comma = rest.find(',');
      std::uint64_t one = 0;
      if (!hrp::parse_length(hrp::trim(rest.substr(0, comma)), one) ||
          (has_length && one != length))
        return refuse(400, "invalid Content-Length");
      has_length = true;
      length = one;
      if (comma == std::string_view::npos) break;
      rest.remove_prefix(comma + 1);
    }
  }
  if (head.field("transfer-encoding") != nullptr) {
    // Both: the request smuggling case of RFC 9112 Sec. 6.3, item 3.
    if (has_length) return refuse(400, "both Transfer-Encoding and Content-Length");
    framing.kind = BodyFraming::Kind::unframed;
    return framing;
  }
  if (length > limits.max_body)
    return refuse(413, "request body longer than " + std::to_string(limits.max_body) +
                           " bytes; prtr view takes no request body");
  if (length > 0) {
    framing.kind = BodyFraming::Kind::length;
    framing.length = length;
  }
  return framing;
}

const char* status_text(int status) {
  switch (status) {
    case 200:
      return "OK";
    case 204:
      return "No Content";
    case 400:
      return "Bad Request";
    case 404:
      return "Not Found";
    case 405:
      return "Method Not Allowed";
    case 408:
      return "Request Timeout";
    case 413:
      return "Content Too Large";
    case 414:
      return "URI Too Long";
    case 421:
      return "Misdirected Request";
    case 431:
      return "Request Header Fields Too Large";
    case 500:
      return "Internal Server Error";
    case 501:
      return "Not Implemented";
    case 503:
      return "Service Unavailable";
    case 505:
      return "HTTP Version Not Supported";
    default:
      return "Unknown";
  }
}

}  // namespace viewer::detail
