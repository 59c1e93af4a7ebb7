// meshes/subdivide.h: refine a mesh by Loop subdivision (OpenMesh's LoopT). Big test inputs for the
// streaming bake are made this way from a real scan (docs/ARCHITECTURE.md, "Scale"); they are
// generated, never committed.
#pragma once

#include "meshes/mesh.h"

namespace meshes {

// `steps` rounds of Loop subdivision of positions and triangles (frames are dropped). A
// closed manifold mesh gains one vertex per edge and four triangles per triangle each round.
// Throws MeshError when a triangle cannot join an edge-manifold surface, naming it.
Mesh loop_subdivide(const Mesh& mesh, int steps);

}  // namespace meshes
