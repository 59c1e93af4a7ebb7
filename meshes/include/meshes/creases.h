// meshes/creases.h: hard edges for meshes whose file gives no normals. Where the faces on
// either side of an edge meet at more than a crease angle, the vertices of that edge are split
// so that each side gets its own normal (the "auto smooth" of modelling tools); elsewhere the
// normal stays smooth (docs/ARCHITECTURE.md, "Normals and creases").
#pragma once

#include "meshes/mesh.h"

#include <cstddef>

namespace meshes {

// All smooth by default. Blender's auto-smooth angle (30 degrees) keeps machined parts hard,
// but scanned surfaces have creases too: the glmark2 bunny would split 1,348 vertices at
// 30 degrees (1,331 at 60, a few even at 120, where it folds back on itself), and the
// folded fans become vertices that see only the inside of the body (black); the low-poly
// horse would gain 43% vertices. Files with their own normals keep them, whatever this
// says (docs/ARCHITECTURE.md, "Normals and creases").
inline constexpr double kDefaultCreaseAngleDeg = 180.0;

// Splits every vertex whose incident faces fall into more than one smooth fan: two faces
// sharing an edge are in the same fan when their normals differ by at most `angle_deg`
// (0: every edge between faces that are not exactly coplanar is hard; 180: no edge is).
// The first fan of a vertex (in triangle order) keeps
// its index; the others get new vertices at bit-identical positions, appended in order, so
// a mesh without creases is left exactly as it was. Frames are not touched (recompute
// them). Returns the vertices added.
std::size_t split_creases(Mesh& mesh, double angle_deg);

}  // namespace meshes
