// meshes/charts.h: cutting a mesh into charts for a texture atlas, each a topological disk of
// triangles whose normals stay within a cone, so that a least-squares conformal map
// (meshes/conformal_map.h) flattens it with little area distortion.
//
// Charts grow one at a time from a seed over edge adjacency, the triangle whose normal is
// closest to the chart's area-weighted mean normal first, as long as that normal stays within
// the cone: region growing with a planarity criterion, after the chart growing of Lévy et al.
// ("Least Squares Conformal Maps for Automatic Texture Atlas Generation", SIGGRAPH 2002,
// Sec. 3.2) and the normal-cone proxies of Julius, Kraevoy and Sheffer ("D-Charts:
// Quasi-Developable Mesh Segmentation", Eurographics 2005). A triangle joins only if the
// chart stays a disk: across one edge when its third vertex is not yet on the chart, or
// across two edges (it fills a notch). Vertices are the same point when
// meshes::group_equal_positions says so, so split vertices do not cut charts.
#pragma once

#include "meshes/mesh.h"

#include <array>
#include <vector>

namespace meshes {

struct TriangleAdjacency {
  // neighbour[t][c]: the triangle across edge (corner c, corner c + 1) of t, or -1 when the
  // edge is on the border, has more than two triangles, joins two triangles of opposite
  // orientations, or either triangle is degenerate (zero area or a repeated point).
  std::vector<std::array<int, 3>> neighbour;
  std::vector<std::uint32_t> point;  // per mesh vertex: its point (group_equal_positions)
  std::vector<char> degenerate;      // per triangle
};
TriangleAdjacency triangle_adjacency(const Mesh& mesh);

// Chart id per triangle, numbered densely from 0 in order of their seeds (the lowest
// triangle not yet in a chart). cone_degrees in (0, 180).
std::vector<int> grow_charts(const Mesh& mesh, const TriangleAdjacency& adjacency,
                             double cone_degrees);

// A chart's triangles cut in two connected parts: the triangles nearer (along adjacency,
// centroid to centroid) to one or the other of two far-apart seeds. Triangles the chart's
// adjacency does not connect to either seed form further parts. Needs at least 2 triangles.
std::vector<std::vector<int>> split_chart(const Mesh& mesh, const TriangleAdjacency& adjacency,
                                          const std::vector<int>& triangles);

}  // namespace meshes
