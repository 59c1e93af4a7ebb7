// cpca/geometry.h: the mesh geometry some compression steps use (geometry coherence, the
// overdraw-aware reassignment, triangle metrics, super-clusters), as plain arrays so that cpca
// does not depend on the mesh module's types.
#pragma once

#include <Eigen/Core>

#include <array>
#include <cstdint>
#include <vector>

namespace cpca {

using TriangleIndices = std::array<std::uint32_t, 3>;

struct Geometry {
  std::vector<Eigen::Vector3f> positions;  // one per vertex, same order as the data rows
  std::vector<TriangleIndices> triangles;  // counter-clockwise, indices < positions.size()
};

}  // namespace cpca
