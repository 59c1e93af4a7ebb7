// meshes/conformal_map.h: least-squares conformal maps (Lévy, Petitjean, Ray, Maillot, "Least
// Squares Conformal Maps for Automatic Texture Atlas Generation", SIGGRAPH 2002, Sec. 4) of
// one chart, and the check that a chart's map is an embedding (what a texture atlas needs).
//
// A chart is given by its own vertices (positions) and triangles over them (counter-clockwise
// seen from the front, as meshes/mesh.h). Its map minimises the conformal energy, the
// area-weighted squared failure of the Cauchy-Riemann equations, grad v = n x grad u, over
// its triangles, with two vertices far apart pinned (Sec. 4.3): a planar chart comes out as
// a similarity of the plane, energy zero.
#pragma once

#include <Eigen/Core>

#include <array>
#include <vector>

namespace meshes {

using ChartTriangle = std::array<int, 3>;

// Texture coordinates per chart vertex, in the units of the positions (the pinned pair keeps
// its 3D distance). Empty when the system is singular (a degenerate triangle, a vertex in
// no triangle, a chart of fewer than 3 vertices) or the solution is not finite.
std::vector<Eigen::Vector2d> conformal_map(const std::vector<Eigen::Vector3d>& positions,
                                           const std::vector<ChartTriangle>& triangles);

// sum over triangles of area x |grad v - n x grad u|^2 (the energy LSCM minimises), divided
// by sum of area x (|grad u|^2 + |grad v|^2) so that it does not depend on the scale: 0 for
// a conformal map, 1 for a collapse onto a line.
double conformal_energy(const std::vector<Eigen::Vector3d>& positions,
                        const std::vector<ChartTriangle>& triangles,
                        const std::vector<Eigen::Vector2d>& uv);

// Whether the map is a one-to-one image of a topological disk: every triangle keeps its
// orientation with positive area, every edge has at most two triangles (opposite
// directions), the boundary is one simple loop that no other boundary edge touches, and
// V - E + F = 1. With positive triangles and a simple boundary, the boundary's winding number
// (0 or 1) counts the preimages of every point, so no two triangles overlap.
bool is_embedded_disk(const std::vector<Eigen::Vector2d>& uv,
                      const std::vector<ChartTriangle>& triangles);

}  // namespace meshes
