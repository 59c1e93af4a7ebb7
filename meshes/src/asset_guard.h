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
#include <vector>

namespace meshes::detail {

// Limits on what is handed to Assimp; a file past one is refused with the limit named.
inline constexpr std::uint64_t kMaxAssetBytes = std::uint64_t{256} << 20;   // file, buffer
inline constexpr std::uint64_t kMaxDataUriBytes = std::uint64_t{64} << 20;  // decoded
inline constexpr int kMaxJsonDepth = 64;
inline constexpr int kMaxNodeDepth = 256;
inline constexpr int kMax3dsDepth = 32;
// What a glTF scene may amount to once instanced: every use of a mesh is copied when the
// scene is flattened, and Assimp makes a mesh of every primitive and a node of every use.
// 16 M vertices is past the largest mesh the bake is documented for (10 M).
inline constexpr std::uint64_t kMaxSceneVertices = std::uint64_t{1} << 24;
inline constexpr std::uint64_t kMaxSceneNodes = std::uint64_t{1} << 20;
inline constexpr std::uint64_t kMaxPrimitives = std::uint64_t{1} << 16;

// The files a glTF file refers to (external buffers), each as its URI is written in the
// file and as the path it was checked at (percent-decoded, beside the .gltf). Assimp opens
// the URI as written; read_assimp gives it the checked file instead.
struct ReferencedFile {
  std::string uri;
  std::filesystem::path checked;
};
using ReferencedFiles = std::vector<ReferencedFile>;

// Each returns an empty string when the file may go to Assimp, else the problem (without
// the path) and what to do.
// The glTF checks add the files the asset refers to to `referenced`.
std::string check_gltf(const std::filesystem::path& path, std::uint64_t size,
                       ReferencedFiles& referenced);
std::string check_glb(const std::filesystem::path& path, std::uint64_t size,
                      ReferencedFiles& referenced);
std::string check_3ds(const std::filesystem::path& path, std::uint64_t size);

}  // namespace meshes::detail
