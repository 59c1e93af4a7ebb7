// libFuzzer target for prtr view's request head parser (viewer/src/http_request.h), the one
// piece of the viewer that reads bytes from the network. Beyond crashes and sanitizer reports
// it checks the parser's contract, aborting when one fails:
// - a complete head's length lies within the input, and the head alone parses to the same
//   length (the bytes after it, a body or the next request, never change where it ends);
// - every strict prefix of a complete head is incomplete (neither complete nor refused), so
//   the answer never depends on how the head was cut into reads (checked at a few cut
//   points, not all, to keep it fast);
// - a refusal carries one of the documented statuses and a one-line reason.
// The input is parsed under the default limits and under small ones, so the 414/431 paths
// are reached with short inputs.
#include "http_request.h"

#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <string_view>

namespace {

using viewer::detail::HeadParse;
using viewer::detail::HttpLimits;

[[noreturn]] void fail(const char* what) {
  std::fprintf(stderr, "fuzz_http_request: %s\n", what);
  std::abort();
}

void check(std::string_view input, const HttpLimits& limits) {
  const HeadParse p = viewer::detail::parse_request_head(input, limits);
  if (p.state == HeadParse::State::refused) {
    const int s = p.status;
    if (s != 400 && s != 414 && s != 431 && s != 505) fail("undocumented refusal status");
    if (p.reason.empty() || p.reason.find('\n') != std::string::npos) fail("reason not one line");
    return;
  }
  if (p.state != HeadParse::State::complete) return;
  if (p.length == 0 || p.length > input.size()) fail("complete head length out of range");
  const std::string_view head = input.substr(0, p.length);
  const HeadParse alone = viewer::detail::parse_request_head(head, limits);
  if (alone.state != HeadParse::State::complete || alone.length != p.length)
    fail("the head alone parses differently");
  for (const std::size_t cut : {p.length - 1, p.length / 2, p.length / 3}) {
    if (cut >= p.length) continue;
    if (viewer::detail::parse_request_head(head.substr(0, cut), limits).state !=
        HeadParse::State::need_more)
      fail("a strict prefix of a head was not incomplete");
  }
  const viewer::detail::BodyFraming framing = viewer::detail::body_framing(p.head, limits);
  if (framing.kind == viewer::detail::BodyFraming::Kind::length &&
      (framing.length == 0 || framing.length > limits.max_body))
    fail("body length out of range");
  (void)p.head.keep_alive();
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string_view input(reinterpret_cast<const char*>(data), size);
  check(input, HttpLimits{});
  HttpLimits small;
  small.max_target = 16;
  small.max_header_bytes = 64;
  small.max_header_fields = 3;
  small.max_body = 8;
  check(input, small);
  return 0;
}
