// meshes/procedural.h: meshes built in code, for tests and examples. All come back with
// frames computed and pass validate(). Parameters that cannot make a mesh (non-positive
// sizes, fewer than 3 segments, a torus with r >= R, a sphere not above the plane) throw
// std::invalid_argument.
#pragma once

#include "meshes/mesh.h"

namespace meshes {

// UV sphere centred at `center`, +Y pole axis; `segments` around, `rings` pole to pole.
Mesh make_sphere(float radius = 1.f, int segments = 32, int rings = 16,
                 const Vec3& center = Vec3::Zero());

// Torus about the +Y axis: major radius R, minor radius r.
Mesh make_torus(float major_radius = 1.f, float minor_radius = 0.35f, int segments = 48,
                int sides = 24);

// Square grid in the XZ plane at height y, normal +Y, side length `size`, centred at origin.
Mesh make_plane(float size = 4.f, int subdivisions = 16, float y = 0.f);

// Occluder scene: a ground plane (y = 0, side `plane_size`) with a sphere of `radius`
// whose centre is `height` above it. A point on the plane straight below the sphere sees
// the sphere subtend a cone of half-angle asin(radius / height) about +Y. Needs
// height > radius.
Mesh make_plane_and_sphere(float plane_size = 6.f, int plane_subdivisions = 24, float radius = 0.5f,
                           float height = 1.5f, int segments = 32, int rings = 16);

// Open box: five faces of the cube [-s/2, s/2]^3 with the +Y face missing, normals facing
// inward, so the inside is a concave receiver; each face is a `subdivisions`^2 grid.
Mesh make_open_box(float size = 2.f, int subdivisions = 8);

// Concatenates meshes (indices offset), then recomputes frames.
Mesh merge(const std::vector<Mesh>& parts);

}  // namespace meshes
