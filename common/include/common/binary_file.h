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

}  // namespace common
