// common/binary_file.h: the pieces every versioned binary file of prtr (.prtx, .prtc) reads
// and writes the same way: fixed-size little-endian headers, the checks a file must pass
// before its bytes are trusted, and readable renderings of raw bytes for error messages.
#pragma once

#include <array>
#include <bit>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <string>
#include <type_traits>

namespace common {

static_assert(std::endian::native == std::endian::little,
              "prtr's file formats are little-endian and written by memcpy");

template <class T, std::size_t N>
void put_field(std::array<unsigned char, N>& header, std::size_t offset, T value) {
  static_assert(std::is_trivially_copyable_v<T>);
  std::memcpy(header.data() + offset, &value, sizeof(T));
}

template <class T, std::size_t N>
T get_field(const std::array<unsigned char, N>& header, std::size_t offset) {
  T value;
  std::memcpy(&value, header.data() + offset, sizeof(T));
  return value;
}

// "0x0123456789abcdef"
std::string hex64(std::uint64_t value);

// Printable ASCII kept, everything else as \xNN (for magic numbers in messages).
std::string printable(const char* bytes, std::size_t count);

// An open binary file and its size, or the problem that stops it from being read, phrased as
// "<problem>; <fix>" without the path (the caller prefixes it and throws its own error type).
// `what` names the kind ("transfer file"), `made_by` the fix ("the .prtx file written by
// prtr bake"), `create` how to make one ("create it with prtr bake").
struct OpenedFile {
  std::ifstream stream;
  std::uintmax_t size = 0;
  std::string problem;  // empty when the file is open
};
OpenedFile open_binary(const std::filesystem::path& path, const std::string& what,
                       const std::string& made_by, const std::string& create);

// The skeleton every versioned prtr file shares (docs/FORMATS.md): a 128-byte header with an
// 8-byte magic at 0, the u32 format version at 8, the u32 header size at 12 and, in its last
// 8 bytes, the FNV-1a checksum of the bytes before them. One owner for the checks and their
// wording, so .prtx and .prtc refuse a bad file in the same words.
inline constexpr std::size_t kVersionedHeaderBytes = 128;
using VersionedHeader = std::array<unsigned char, kVersionedHeaderBytes>;

struct VersionedFormat {
  const char* what;    // "transfer file"
  const char* file;    // ".prtx file written by prtr bake"
  const char* create;  // "create it with prtr bake"
  const char* remedy;  // "bake it again with prtr bake"
  std::array<char, 8> magic;
  std::uint32_t version;
  // The oldest version the reader still accepts (it then reads the older layout itself);
  // 0: only `version`.
  std::uint32_t oldest_version = {};
};

// Zero bytes but the magic, version and header size; the format fills its own fields.
VersionedHeader begin_header(const VersionedFormat& format);
// Writes the header checksum; the last step before the header goes to disk.
void seal_header(VersionedHeader& header);

// The open file with its header read, or the problem (as for open_binary) with the format's
// remedy: not found, truncated header, wrong magic, other version, wrong header size. The
// format's own fields are not looked at; the header checksum is checked by
// header_checksum_problem once the caller has checked its fields, so that a damaged field is
// named rather than reported as a bad checksum.
struct OpenedVersionedFile {
  std::ifstream stream;
  std::uintmax_t size = 0;
  VersionedHeader header{};
  std::string problem;
};
OpenedVersionedFile open_versioned(const std::filesystem::path& path,
                                   const VersionedFormat& format);

// The format version the header records (open_versioned has checked it is one it reads).
std::uint32_t header_version(const VersionedHeader& header);

// Empty when the recorded header checksum matches.
std::string header_checksum_problem(const VersionedHeader& header, const VersionedFormat& format);
// "<part> damaged (checksum X, the header records Y); <remedy>", or empty when they match.
std::string checksum_problem(const char* part, std::uint64_t computed, std::uint64_t recorded,
                             const VersionedFormat& format);
// Truncated or trailing bytes, or empty when `found` is `expected`.
std::string file_size_problem(std::uint64_t expected, std::uintmax_t found,
                              const VersionedFormat& format);

}  // namespace common
