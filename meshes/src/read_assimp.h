// meshes/src/read_assimp.h (private): glTF 2.0 (.gltf, .glb) and 3DS through Assimp, the one
// file that includes it. Callers run the guards of asset_guard.h first.
//
// The scene is flattened into world space: every node's meshes are transformed by the
// product of the transforms from the root down to it, and a mesh that several nodes use is
// copied once per node. Positions and polygons are taken, and with `keep_normals` the
// vertex normals when every mesh has them (glTF's NORMAL; 3DS stores none, Assimp derives
// them from smoothing groups, so for 3DS the caller asks for none and load.cpp computes
// them like those of every other format without normals). 3DS is Z-up: Assimp's 3DS
// importer rotates its root node to +Y-up, (x, y, z) -> (x, z, -y), which keeps the
// handedness and the winding.
#pragma once

#include "read_strict.h"

#include <filesystem>
#include <string>

namespace meshes::detail {

// Most vertices a flattened scene may have (instancing can multiply a small file's).
inline constexpr std::uint64_t kMaxSceneVertices = std::uint64_t{1} << 26;

// Returns an empty string on success, else the problem (without the path) and what to do.
std::string read_assimp(const std::filesystem::path& path, RawPolygons& out, bool keep_normals);

}  // namespace meshes::detail
