// meshes/src/atlas_detail.h: what the two ways of building an atlas (meshes/atlas.h) share:
// the size limits, the texel rule for a chart's place in the atlas, and the nearest point of
// a triangle. Coordinates are in texels: texel x covers [x, x + 1), its centre is x + 0.5,
// and a bilinear lookup at p reads texels floor(p - 0.5) and floor(p - 0.5) + 1 on each axis,
// so texel i is read by the points of [i - 0.5, i + 1.5). A cell of S texels at X that holds
// its chart between X + 0.5 + d and X + S - 0.5 - d (an inset d of a hundredth of a texel,
// so that float texture coordinates, rounded, still read only the cell's texels) is read by
// its chart's lookups only in texels X .. X + S - 1, so cells can touch.
#pragma once

#include "meshes/atlas.h"

#include <Eigen/Core>

namespace meshes::atlas_detail {

inline constexpr int kMinSize = 4, kMaxSize = 8192;
inline constexpr double kInset = 0.01;  // d above, in texels

// Throws std::invalid_argument for a size outside [kMinSize, kMaxSize] or an empty mesh.
void check_atlas_input(const Mesh& mesh, int width, int height);

// The point of triangle (a, b, c) nearest to p, as weights of a, b and c.
Eigen::Vector3d nearest_weights(const Eigen::Vector2d& p, const Eigen::Vector2d& a,
                                const Eigen::Vector2d& b, const Eigen::Vector2d& c);

Atlas make_conformal_atlas(const Mesh& mesh, int width, int height);

}  // namespace meshes::atlas_detail
