// render/slf_reference.h: the surface light field's reconstruction on the CPU, the reference
// the one-pass GL renderer (render/slf_renderer.h) is held to. SLF paper, Sec. 3.3 (Eq. 7).
//
// Radiance at atlas point uv toward direction d (from the surface toward the viewer):
//  - in space, bilinear over the four texels around uv (texel x's centre at (x + 0.5) / X,
//    indices clamped to the map), each texel reconstructed in its own cluster: the paper's
//    four nearest surface-map rows, with bilinear weights where it takes inverse distances
//    (inverse distances do not sum to one and jump when the four texels change; bilinear
//    weights are continuous across texel boundaries and reproduce a texel at its centre);
//  - in direction, bilinear in the grid's (xi1, xi2) = Eq. 2 of d, wrapping around in the
//    azimuth xi1 and clamping at the poles. The paper weights the four nearest grid
//    directions by exp(d . d_i); those weights differ by at most a factor e^(1 - cos(cell)),
//    so they average the four almost equally even at a grid direction (a box blur that never
//    returns the stored value), and they need four arctangent-free dot products per tap that
//    a texture unit cannot do. Bilinear weights interpolate, are continuous across cells and
//    the seam, and are what the GPU's filtering of a view-map tile with a one-texel gutter
//    gives in one fetch, so the GL path and this reference compute the same function.
//  - Every texel uses the fragment's own direction (slf_radiance), or, as the paper does, its
//    own: from the texel's surface point toward the eye (slf_radiance_toward, what
//    texture-space shading computes). The two differ by the angle a texel subtends at the eye.
//  - A grid of reflected or local directions (prt/slf_directions.h) takes each texel's
//    direction into the grid's space at that texel's normal (SlfModel::texel_normals) before
//    the lookup, in both forms: mirrored about it, or into its local frame.
//  - Negative radiance is clamped to 0 per channel once, after the spatial blend: CPCA's
//    reconstruction of a noisy matrix undershoots where the data is near zero (a silhouette
//    whose red and green go below zero shows as blue dots). Clamping each texel before the
//    blend would suit the data slightly better (a negative texel would no longer darken its
//    neighbours), but the GL path's shared-cluster fast path reconstructs the four texels of
//    one cluster as one interpolated weight vector (the same sum by linearity only), so a
//    per-texel clamp would cost it its single reconstruction; after the blend both paths
//    clamp the same function at the same point.
// Texels with cluster -1 (no triangle reads them; the atlas never puts one under a lookup
// inside a triangle) and texels of zero weight contribute nothing and are not read.
#pragma once

#include "render/camera.h"
#include "render/image.h"
#include "render/slf_model.h"

#include <Eigen/Core>

namespace render {

// Where a direction in the grid's axes (prt::slf_grid_space) falls on the grid: the two
// azimuth columns (wrapped) and the two polar rows (clamped) around it with the weight of
// the second of each pair. One definition for the CPU reference and for tests of the GL
// path's tile addressing.
struct SlfDirectionTaps {
  int column[2] = {0, 0}, row[2] = {0, 0};
  double column_weight = 0, row_weight = 0;  // of column[1], row[1]
};
SlfDirectionTaps slf_direction_taps(const prt::SlfGrid& grid,
                                    const Eigen::Vector3d& grid_direction);

// Radiance (linear RGB) from atlas point `uv` toward `direction` (need not be unit).
// The model must be valid (SlfModel::validate); uv outside [0, 1]^2 clamps to the border
// texels.
Eigen::Vector3f slf_radiance(const SlfModel& model, const Eigen::Vector2f& uv,
                             const Eigen::Vector3d& direction);

// The same with each texel reconstructed toward `eye` from its own surface point
// (SlfModel::texel_positions).
Eigen::Vector3f slf_radiance_toward(const SlfModel& model, const Eigen::Vector2f& uv,
                                    const Eigen::Vector3d& eye);

struct SlfReferenceOptions {
  bool cull_back_faces = true;                           // as the GL path's option
  Eigen::Vector3f background = Eigen::Vector3f::Zero();  // misses (alpha 0)
  bool texel_directions = false;  // slf_radiance_toward: texture-space shading's image
};

// The image the GL path draws, by ray casting: each pixel centre's ray (Camera::
// pixel_direction) against every triangle within the clip planes, the nearest hit's
// interpolated uv and the ray reversed as the direction; alpha is coverage. A solid
// background only (the GL path's probe background is its own pass). Parallel over rows;
// meant for tests and small images.
Image render_slf_reference(const SlfModel& model, const Camera& camera,
                           const SlfReferenceOptions& options = {});

}  // namespace render
