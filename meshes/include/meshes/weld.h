// meshes/weld.h: grouping vertices by position, the one definition of "the same point" that
// loading (welding) and baking (ray origins shared by split vertices) both rely on.
//
// Two positions are the same point when their coordinates compare equal as floats, so +0
// and -0 match and every other value matches only itself (positions are finite: Mesh
// validation refuses NaN and Inf).
#pragma once

#include "meshes/mesh.h"

#include <cstdint>
#include <vector>

namespace meshes {

struct PositionGroups {
  // group[v] = the group of vertex v. Groups are numbered densely in order of first
  // occurrence: vertex 0 is in group 0, and the first vertex at a new point opens the next.
  std::vector<std::uint32_t> group;
  // first[g] = the lowest-numbered vertex in group g.
  std::vector<std::uint32_t> first;

  std::size_t count() const { return first.size(); }
};

PositionGroups group_equal_positions(const std::vector<Vec3>& positions);

// remap[v] = the vertex v merges into (v itself when it survives) when positions closer than
// `tolerance` x the diagonal of `box` (their bounding box) are welded; see load.cpp for the
// grid. A negative tolerance welds nothing; one too small for the grid welds equal
// positions only (group_equal_positions).
std::vector<std::uint32_t> weld_map(const std::vector<Vec3>& positions, double tolerance,
                                    const Bounds& box);

}  // namespace meshes
