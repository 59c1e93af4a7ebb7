// meshes/src/asset_guard.h (private): checks a glTF 2.0 (.gltf, .glb) or 3DS file before
// Assimp reads it.
//
// Assimp trusts what a file claims: its glTF importer sizes buffers from byteLength and
// accessor counts, parses JSON recursively, follows buffer URIs anywhere and recurses over
// the node tree. These guards bound all of that from the file itself, without allocating
// more than the file's own size; what is left for Assimp is a file whose every claimed size
// fits in the bytes that exist. Which guard covers what is listed in docs/ROBUSTNESS.md.
#pragma once

#include <cstdint>
#include <filesystem>
#include <string>

namespace meshes::detail {

// Limits on what is handed to Assimp; a file past one is refused with the limit named.
inline constexpr std::uint64_t kMaxAssetBytes = std::uint64_t{256} << 20;   // file, buffer
inline constexpr std::uint64_t kMaxDataUriBytes = std::uint64_t{64} << 20;  // decoded
inline constexpr int kMaxJsonDepth = 64;
inline constexpr int kMaxNodeDepth = 256;
inline constexpr int kMax3dsDepth = 32;

// Each returns an empty string when the file may go to Assimp, else the problem (without
// the path) and what to do.
std::string check_gltf(const std::filesystem::path& path, std::uint64_t size);
std::string check_glb(const std::filesystem::path& path, std::uint64_t size);
std::string check_3ds(const std::filesystem::path& path, std::uint64_t size);

}  // namespace meshes::detail
