// meshes/write_ply.h: write a mesh (positions and triangles) as binary PLY, the format the
// subdivided test inputs are kept in; meshes::load_mesh reads it back.
#pragma once

#include "meshes/mesh.h"

#include <filesystem>

namespace meshes {

// Binary little-endian PLY (float x y z; uchar-counted int faces), written atomically.
void write_ply(const std::filesystem::path& path, const Mesh& mesh);

}  // namespace meshes
