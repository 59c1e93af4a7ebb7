// common/hash.h: FNV-1a 64-bit, the content hash used to tie a bake to its mesh and a
// compressed file to its bake. Not cryptographic; it detects staleness, not tampering.
#pragma once

#include <cstddef>
#include <cstdint>

namespace common {

inline constexpr std::uint64_t kFnvOffset = 0xcbf29ce484222325ULL;

// Continues a hash over `bytes` bytes; start from kFnvOffset.
std::uint64_t fnv1a(const void* data, std::size_t bytes, std::uint64_t hash = kFnvOffset);

}  // namespace common
