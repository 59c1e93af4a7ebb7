// meshes/frames.h: per-vertex normals and tangent frames.
//
// Normals are the weighted sum of incident face normals (by corner angle or face area;
// angle weighting falls back to area weighting where it would turn a vertex's normal away
// from most of its incident area).
// Tangents follow one global reference axis projected into each tangent plane, so the frame
// field is continuous wherever the surface is, except at the (unavoidable, hairy-ball) points
// where the normal is parallel to the reference axis. The axis is chosen per mesh among
// X, Y, Z as the one fewest normals point along, which keeps those points rare.
#pragma once

#include "meshes/mesh.h"

namespace meshes {

enum class NormalWeighting { kAngle, kArea };

// Fills normals, tangents and bitangents. Vertices no face touches get an arbitrary frame.
void compute_frames(Mesh& mesh, NormalWeighting weighting = NormalWeighting::kAngle);

// Keeps the normals already in `mesh` (normalised; missing or zero ones become +Y) and fills
// tangents and bitangents by the same rule: for normals a file supplies.
void compute_tangents(Mesh& mesh);

// An orthonormal tangent for normal n: the reference axis projected into the plane of n,
// falling back to a second axis where n is (nearly) parallel to the reference.
Vec3 tangent_from_reference(const Vec3& n, const Vec3& reference);

}  // namespace meshes
