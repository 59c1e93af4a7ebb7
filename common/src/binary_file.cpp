#include "common/binary_file.h"

#include <cstdio>

namespace common {
namespace fs = std::filesystem;

std::string hex64(std::uint64_t value) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "0x%016llx", static_cast<unsigned long long>(value));
  return buf;
}

std::string printable(const char* bytes, std::size_t count) {
  std::string s;
  for (std::size_t i = 0; i < count; ++i) {
    const auto c = static_cast<unsigned char>(bytes[i]);
    if (c >= 0x20 && c < 0x7f && c != '"' && c != '\\') {
      s += static_cast<char>(c);
    } else {
      char buf[8];
      std::snprintf(buf, sizeof buf, "\\x%02x", c);
      s += buf;
    }
  }
  return s;
}

OpenedFile open_binary(const fs::path& path, const std::string& what, const std::string& made_by,
                       const std::string& create) {
  OpenedFile f;
  // File-system problems first, each with its own fix.
  std::error_code ec;
  const fs::file_status status = fs::status(path, ec);
  if (ec && ec != std::errc::no_such_file_or_directory) {
    f.problem = "cannot be inspected (" + ec.message() + "); check the path and permissions";
  } else if (!fs::exists(status)) {
    f.problem = "no such " + what + "; check the path, or " + create;
  } else if (fs::is_directory(status)) {
    f.problem = "is a directory, not a " + what + "; name " + made_by;
  } else if (!fs::is_regular_file(status)) {
    f.problem = "is not a regular file; name " + made_by;
  } else {
    f.size = fs::file_size(path, ec);
    if (ec) {
      f.problem = "cannot read its size (" + ec.message() + "); check permissions";
    } else {
      f.stream.open(path, std::ios::binary);
      if (!f.stream) f.problem = "cannot be opened for reading; check its permissions";
    }
  }
  return f;
}

}  // namespace common
