#include "common/binary_file.h"

#include "common/hash.h"

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

namespace {
constexpr std::size_t kOffMagic = 0;
constexpr std::size_t kOffVersion = 8;
constexpr std::size_t kOffHeaderBytes = 12;
constexpr std::size_t kOffHeaderChecksum = kVersionedHeaderBytes - 8;

// The problem with an open header's identity, or empty.
std::string identity_problem(const VersionedHeader& h, const VersionedFormat& format) {
  const std::string remedy = format.remedy;
  if (std::memcmp(h.data() + kOffMagic, format.magic.data(), format.magic.size()) != 0) {
    return "not a prtr " + std::string(format.what) + " (it starts with \"" +
           printable(reinterpret_cast<const char*>(h.data()), format.magic.size()) + "\", not \"" +
           std::string(format.magic.data(), format.magic.size()) + "\"); name a " + format.file;
  }
  const auto version = get_field<std::uint32_t>(h, kOffVersion);
  const std::uint32_t oldest = format.oldest_version ? format.oldest_version : format.version;
  if (version < oldest || version > format.version) {
    const bool newer = version > format.version;
    return std::string("written by ") + (newer ? "a newer" : "an older") +
           " prtr version (file format version " + std::to_string(version) +
           "; this prtr reads version" +
           (oldest == format.version ? " " : "s " + std::to_string(oldest) + " to ") +
           std::to_string(format.version) + "); " + (newer ? "use that prtr, or " : "") + remedy +
           " from this version";
  }
  const auto header_bytes = get_field<std::uint32_t>(h, kOffHeaderBytes);
  if (header_bytes != kVersionedHeaderBytes) {
    return "header size " + std::to_string(header_bytes) + " bytes, version " +
           std::to_string(format.version) + " has " + std::to_string(kVersionedHeaderBytes) +
           "; the header is damaged: " + remedy;
  }
  return {};
}
}  // namespace

std::uint32_t header_version(const VersionedHeader& header) {
  return get_field<std::uint32_t>(header, kOffVersion);
}

VersionedHeader begin_header(const VersionedFormat& format) {
  VersionedHeader h{};
  std::memcpy(h.data() + kOffMagic, format.magic.data(), format.magic.size());
  put_field<std::uint32_t>(h, kOffVersion, format.version);
  put_field<std::uint32_t>(h, kOffHeaderBytes, std::uint32_t(kVersionedHeaderBytes));
  return h;
}

void seal_header(VersionedHeader& header) {
  put_field<std::uint64_t>(header, kOffHeaderChecksum, fnv1a(header.data(), kOffHeaderChecksum));
}

OpenedVersionedFile open_versioned(const fs::path& path, const VersionedFormat& format) {
  OpenedVersionedFile f;
  OpenedFile opened =
      open_binary(path, format.what, std::string("the ") + format.file, format.create);
  if (!opened.problem.empty()) {
    f.problem = opened.problem;
    return f;
  }
  f.stream = std::move(opened.stream);
  f.size = opened.size;
  const auto truncated = [&](std::uintmax_t found) {
    return "truncated header: the file has " + std::to_string(found) + " bytes, a " + format.what +
           " at least " + std::to_string(kVersionedHeaderBytes) + "; " + format.remedy;
  };
  if (f.size < kVersionedHeaderBytes) {
    f.problem = truncated(f.size);
    return f;
  }
  f.stream.read(reinterpret_cast<char*>(f.header.data()), kVersionedHeaderBytes);
  if (std::size_t(f.stream.gcount()) != kVersionedHeaderBytes) {
    f.problem = truncated(std::size_t(f.stream.gcount()));
    return f;
  }
  f.problem = identity_problem(f.header, format);
  return f;
}

std::string checksum_problem(const char* part, std::uint64_t computed, std::uint64_t recorded,
                             const VersionedFormat& format) {
  if (computed == recorded) return {};
  return std::string(part) + " damaged (checksum " + hex64(computed) + ", the header records " +
         hex64(recorded) + "); " + format.remedy;
}

std::string header_checksum_problem(const VersionedHeader& header, const VersionedFormat& format) {
  return checksum_problem("header", fnv1a(header.data(), kOffHeaderChecksum),
                          get_field<std::uint64_t>(header, kOffHeaderChecksum), format);
}

std::string file_size_problem(std::uint64_t expected, std::uintmax_t found,
                              const VersionedFormat& format) {
  const std::string remedy = format.remedy;
  if (found == expected) return {};
  if (found < expected) {
    return "truncated: expected " + std::to_string(expected) + " bytes, found " +
           std::to_string(found) + " (the write or copy was interrupted); copy it again or " +
           remedy;
  }
  return "trailing bytes: expected " + std::to_string(expected) + " bytes, found " +
         std::to_string(found) + " (" + std::to_string(found - expected) +
         " extra); the file is damaged: " + remedy;
}

}  // namespace common
