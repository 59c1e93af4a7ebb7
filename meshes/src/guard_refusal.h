// meshes/src/guard_refusal.h (private): what the asset guards (asset_guard.h) share. A check
// deep in a file's structure refuses by throwing Refusal; guarded() turns that into the
// problem string the entry points return, after the size limit every asset shares.
#pragma once

#include "asset_guard.h"

#include <cstdint>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <string_view>

namespace meshes::detail {

struct Refusal {
  std::string problem;
};

[[noreturn]] inline void refuse(const std::string& problem) {
  throw Refusal{problem};
}

inline std::string read_all(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  return std::string((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
}

inline std::uint32_t le32(std::string_view b, std::size_t at) {
  const auto* p = reinterpret_cast<const unsigned char*>(b.data() + at);
  return std::uint32_t(p[0]) | (std::uint32_t(p[1]) << 8) | (std::uint32_t(p[2]) << 16) |
         (std::uint32_t(p[3]) << 24);
}

inline std::uint16_t le16(std::string_view b, std::size_t at) {
  const auto* p = reinterpret_cast<const unsigned char*>(b.data() + at);
  return std::uint16_t(p[0] | (p[1] << 8));
}

template <class Check>
std::string guarded(std::uint64_t size, const Check& check) {
  if (size > kMaxAssetBytes) {
    return "the file has " + std::to_string(size) + " bytes, over the " +
           std::to_string(kMaxAssetBytes >> 20) + " MiB limit for glTF and 3DS assets";
  }
  try {
    check();
  } catch (const Refusal& r) {
    return r.problem;
  }
  return {};
}

}  // namespace meshes::detail
