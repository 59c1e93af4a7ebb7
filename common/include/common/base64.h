// common/base64.h: base64 (RFC 4648, the standard alphabet with '=' padding), as glTF data
// URIs carry buffers.
#pragma once

#include <string>
#include <string_view>

namespace common {

std::string base64_encode(std::string_view bytes);

// The bytes of `text`, a whole number of quads of the alphabet with at most two '=' at the
// end; the caller checks that first (a loader names the offending offset in its message).
// A character outside the alphabet decodes as '/'.
std::string base64_decode(std::string_view text);

}  // namespace common
