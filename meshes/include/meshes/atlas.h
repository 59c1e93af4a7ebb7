// meshes/atlas.h: a texture atlas that samples the surface uniformly by area, for the surface
// light field (SLF paper, Sec. 3.1: "uniform sampling of the spatial dimension", so the
// number of samples does not depend on the vertex count).
//
// Every triangle gets its own chart, so texture coordinates are per corner. A texel belongs
// to at most one triangle: the one whose bilinear lookups read it. Texels around a chart (its
// gutter) are sampled at the nearest point of their triangle, so a bilinear lookup anywhere
// inside a triangle reads only texels of that triangle.
#pragma once

#include "meshes/mesh.h"

#include <Eigen/Core>

#include <cstdint>
#include <vector>

namespace meshes {

struct Atlas {
  int width = 0, height = 0;          // texels
  std::vector<Eigen::Vector2f> uv{};  // 3 per triangle (corner 3 t + i), in [0, 1]^2; texel
                                      // x's centre is at (x + 0.5) / width
  // Per texel, row-major (y * width + x): the triangle whose lookups read it (-1: none) and
  // the barycentrics (u, v) of the surface point it samples, p = (1-u-v) p0 + u p1 + v p2.
  std::vector<std::int32_t> texel_triangle{};
  std::vector<Eigen::Vector2f> texel_barycentric{};

  std::size_t used_texels() const;
};

// An atlas of at most width x height texels. Throws std::invalid_argument when the size is
// out of range or too small to give every triangle a chart.
Atlas make_atlas(const Mesh& mesh, int width, int height);

}  // namespace meshes
