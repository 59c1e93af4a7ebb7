// render/slf_model.h: a compressed surface light field as the one-pass renderer reads it
// (SLF paper, Secs. 3.2 and 3.3), in plain arrays so render/ needs no file format.
//
// Radiance leaving surface texel t toward grid direction d (prt/slf_directions.h), channel c:
//   L(t, d, c) = V[cl, 0, d, c] + sum_{j < k} U[t, j] V[cl, 1 + j, d, c],  cl = cluster of t
// which is CPCA's reconstruction, the cluster mean in slice 0 of the view maps and the
// surface map holding the weights. A fragment reads the four texels around its atlas
// coordinate (bilinear in space, each texel with its own cluster) and interpolates each
// between the grid directions around the view.
#pragma once

#include "prt/slf_directions.h"

#include <Eigen/Core>

#include <cstdint>
#include <vector>

namespace render {

struct SlfModel {
  // Geometry, unwelded: corner 3 t + i of triangle t. The atlas gives every triangle its own
  // texels, so corners shared in space have different texture coordinates.
  std::vector<Eigen::Vector3f> positions;  // 3 T
  std::vector<Eigen::Vector3f> normals;    // 3 T (shading the background-free floor, overlays)
  std::vector<Eigen::Vector2f> uv;         // 3 T, atlas coordinates in [0, 1]^2 (texel centre
                                           // x at (x + 0.5) / map_width)

  int map_width = 0, map_height = 0;  // X x Y texels of the surface map
  prt::SlfGrid grid;                  // Z x W directions
  int components = 0;                 // k, PCA terms per cluster
  int clusters = 0;                   // eta

  std::vector<std::int32_t> texel_cluster;  // X Y, row-major (y * X + x); -1: no triangle reads it
  std::vector<float> texel_weights;         // X Y k: the surface map U
  // X Y: the surface point each texel samples (meshes::Atlas::texel_barycentric on its
  // triangle); any finite value where the cluster is -1. Texture-space shading takes a
  // texel's view direction from it, as the paper does per texel.
  std::vector<Eigen::Vector3f> texel_positions;
  // X Y unit shading normals (meshes::texel_normals), where the grid holds reflected or
  // local directions (prt/slf_directions.h): each texel takes its view into the grid's space
  // at its own normal before the grid lookup, as its bake did. Empty for view directions.
  std::vector<Eigen::Vector3f> texel_normals;
  // clusters (k + 1) Z W 3: cluster, slice (0 the mean, 1 + j component j), direction
  // column j Z + i, then RGB. The view maps V.
  std::vector<float> view_maps;

  std::size_t slice_floats() const { return std::size_t(grid.directions()) * 3; }
  const float* view_slice(int cluster, int slice) const {
    return view_maps.data() + (std::size_t(cluster) * (components + 1) + slice) * slice_floats();
  }
  // Throws std::invalid_argument naming the first inconsistent size.
  void validate() const;
};

// For models made by hand (tests, benchmarks) rather than from an atlas: each used texel's
// point is where its centre falls on the triangle whose uv contains it, else on the triangle
// nearest in uv, barycentrics clamped onto it (the atlas's gutter rule, charts aside).
// Needs the geometry, uv, map size and texel_cluster; other texels get (0, 0, 0).
std::vector<Eigen::Vector3f> texel_points_from_uv(const SlfModel& model);
// The same texels' unit normals, from the corners' normals (+Y where they cancel and where
// no triangle reads the texel).
std::vector<Eigen::Vector3f> texel_normals_from_uv(const SlfModel& model);

}  // namespace render
