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

#include "asset_guard.h"
#include "read_strict.h"

#include <filesystem>
#include <string>

namespace meshes::detail {

// Returns an empty string on success, else the problem (without the path) and what to do.
// Assimp may open `path` and the files in `referenced` (as the guard checked them), nothing
// else, and each only if it is still a regular file within the size limit.
std::string read_assimp(const std::filesystem::path& path, const ReferencedFiles& referenced,
                        RawPolygons& out, bool keep_normals);

}  // namespace meshes::detail
