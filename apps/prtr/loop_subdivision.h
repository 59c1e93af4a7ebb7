// apps/prtr/loop_subdivision.h: refine a mesh by Loop subdivision (OpenMesh's LoopT), and
// write the result as binary PLY. Big test inputs for the streaming bake are made this way
// from a real scan (docs/ARCHITECTURE.md, "Scale"); they are generated, never committed.
#pragma once

#include "meshes/mesh.h"

#include <filesystem>

namespace prtr_app {

// `steps` rounds of Loop subdivision of positions and triangles (frames are dropped). A
// closed manifold mesh gains one vertex per edge and four triangles per triangle each round.
// Throws meshes::MeshError when a triangle cannot join an edge-manifold surface, naming it.
meshes::Mesh loop_subdivide(const meshes::Mesh& mesh, int steps);

// Binary little-endian PLY (float x y z; uchar-counted int faces), written atomically.
void write_ply(const std::filesystem::path& path, const meshes::Mesh& mesh);

}  // namespace prtr_app
