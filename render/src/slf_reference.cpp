#include "render/slf_reference.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

namespace render {

SlfDirectionTaps slf_direction_taps(const prt::SlfGrid& grid,
                                    const Eigen::Vector3d& grid_direction) {
  const Eigen::Vector2d xi = prt::slf_grid_coordinates(grid, grid_direction);
  // Column i's centre sits at xi1 = 2 (i + 0.5) / Z and row j's at xi2 = (j + 0.5) / W.
  const double s = xi.x() * 0.5 * grid.azimuth - 0.5, t = xi.y() * grid.elevation - 0.5;
  const double s0 = std::floor(s), t0 = std::floor(t);
  SlfDirectionTaps taps;
  const int i0 = int(s0), j0 = int(t0);
  const int z = grid.azimuth, w = grid.elevation;
  taps.column[0] = ((i0 % z) + z) % z;
  taps.column[1] = (((i0 + 1) % z) + z) % z;
  taps.row[0] = std::clamp(j0, 0, w - 1);
  taps.row[1] = std::clamp(j0 + 1, 0, w - 1);
  taps.column_weight = s - s0;
  taps.row_weight = t - t0;
  return taps;
}

namespace slf_reference_taps {

// One slice of a cluster's view maps at the direction taps, in double.
Eigen::Vector3d view_lookup(const SlfModel& model, int cluster, int slice,
                            const SlfDirectionTaps& taps) {
  const float* v = model.view_slice(cluster, slice);
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  for (int a = 0; a < 2; ++a)
    for (int b = 0; b < 2; ++b) {
      const double weight = (a ? taps.column_weight : 1.0 - taps.column_weight) *
                            (b ? taps.row_weight : 1.0 - taps.row_weight);
      const float* rgb =
          v + (std::size_t(taps.row[b]) * std::size_t(model.grid.azimuth) + taps.column[a]) * 3;
      sum += weight * Eigen::Vector3d(rgb[0], rgb[1], rgb[2]);
    }
  return sum;
}

}  // namespace slf_reference_taps

namespace slf_reference_taps {

// The spatial blend of Eq. 7 with bilinear weights; `taps_of(texel)` gives the direction
// taps that texel is reconstructed at.
template <typename TapsOf>
Eigen::Vector3f blend(const SlfModel& model, const Eigen::Vector2f& uv, const TapsOf& taps_of) {
  const double sx = double(uv.x()) * model.map_width - 0.5;
  const double sy = double(uv.y()) * model.map_height - 0.5;
  const double x0 = std::floor(sx), y0 = std::floor(sy);
  const double fx = sx - x0, fy = sy - y0;
  const int k = model.components;
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  for (int b = 0; b < 2; ++b)
    for (int a = 0; a < 2; ++a) {
      const double weight = (a ? fx : 1.0 - fx) * (b ? fy : 1.0 - fy);
      if (!(weight > 0.0)) continue;
      const int x = std::clamp(int(x0) + a, 0, model.map_width - 1);
      const int y = std::clamp(int(y0) + b, 0, model.map_height - 1);
      const std::size_t texel = std::size_t(y) * std::size_t(model.map_width) + std::size_t(x);
      const int cluster = model.texel_cluster[texel];
      if (cluster < 0) continue;
      const SlfDirectionTaps taps = taps_of(texel);
      Eigen::Vector3d texel_radiance = view_lookup(model, cluster, 0, taps);
      const float* u = model.texel_weights.data() + texel * std::size_t(k);
      for (int j = 0; j < k; ++j)
        texel_radiance += double(u[j]) * view_lookup(model, cluster, 1 + j, taps);
      sum += weight * texel_radiance;
    }
  return sum.cwiseMax(0.0).cast<float>();  // after the blend: render/slf_reference.h
}

}  // namespace slf_reference_taps

namespace slf_reference_taps {

// Texel `texel`'s taps toward the unit view `d` (from its point toward the viewer), taken into
// the grid's space at its normal first (mirrored, or into its local frame).
SlfDirectionTaps texel_taps(const SlfModel& model, std::size_t texel, const Eigen::Vector3d& d) {
  if (!prt::slf_grid_uses_normals(model.grid)) return slf_direction_taps(model.grid, d);
  return slf_direction_taps(
      model.grid, prt::slf_grid_space(model.grid, d, model.texel_normals[texel].cast<double>()));
}

}  // namespace slf_reference_taps

Eigen::Vector3f slf_radiance(const SlfModel& model, const Eigen::Vector2f& uv,
                             const Eigen::Vector3d& direction) {
  if (!prt::slf_grid_uses_normals(model.grid)) {
    const SlfDirectionTaps taps = slf_direction_taps(model.grid, direction);
    return slf_reference_taps::blend(model, uv, [&](std::size_t) { return taps; });
  }
  const Eigen::Vector3d d = direction.normalized();
  return slf_reference_taps::blend(model, uv, [&](std::size_t texel) {
    return slf_reference_taps::texel_taps(model, texel, d);
  });
}

Eigen::Vector3f slf_radiance_toward(const SlfModel& model, const Eigen::Vector2f& uv,
                                    const Eigen::Vector3d& eye) {
  return slf_reference_taps::blend(model, uv, [&](std::size_t texel) {
    return slf_reference_taps::texel_taps(
        model, texel, (eye - model.texel_positions[texel].cast<double>()).normalized());
  });
}

Image render_slf_reference(const SlfModel& model, const Camera& camera,
                           const SlfReferenceOptions& options) {
  camera.validate();
  model.validate();
  const int width = camera.width, height = camera.height;
  const std::size_t triangles = model.positions.size() / 3;
  const Eigen::Matrix4d clip_from_world = camera.clip_from_world();
  const Eigen::Vector3d eye = camera.eye;
  const Eigen::Vector3d forward = (camera.target - camera.eye).normalized();

  // Each triangle's pixel bounding box (the whole image when a corner is behind the eye).
  struct Box {
    int x0, y0, x1, y1;
  };
  std::vector<Box> boxes(triangles);
  for (std::size_t t = 0; t < triangles; ++t) {
    double lo_x = std::numeric_limits<double>::infinity(), lo_y = lo_x, hi_x = -lo_x, hi_y = -lo_x;
    bool behind = false;
    for (int i = 0; i < 3; ++i) {
      const Eigen::Vector4d c =
          clip_from_world * model.positions[3 * t + std::size_t(i)].cast<double>().homogeneous();
      if (!(c.w() > 1e-9)) {
        behind = true;
        break;
      }
      const double px = (c.x() / c.w() * 0.5 + 0.5) * width;
      const double py = (0.5 - c.y() / c.w() * 0.5) * height;  // row 0 at the top
      lo_x = std::min(lo_x, px);
      hi_x = std::max(hi_x, px);
      lo_y = std::min(lo_y, py);
      hi_y = std::max(hi_y, py);
    }
    if (behind) {
      boxes[t] = {0, 0, width - 1, height - 1};
      continue;
    }
    // A pixel is tested when its centre may lie inside: one pixel of slack for rounding.
    boxes[t] = {std::max(0, int(std::floor(lo_x)) - 1), std::max(0, int(std::floor(lo_y)) - 1),
                std::min(width - 1, int(std::ceil(hi_x)) + 1),
                std::min(height - 1, int(std::ceil(hi_y)) + 1)};
  }

  Image image;
  image.width = width;
  image.height = height;
  image.rgba.resize(std::size_t(width) * std::size_t(height) * 4);
  tbb::parallel_for(
      tbb::blocked_range<int>(0, height, 8), [&](const tbb::blocked_range<int>& rows) {
        const int row_count = rows.end() - rows.begin();
        std::vector<double> depth(std::size_t(row_count) * std::size_t(width),
                                  std::numeric_limits<double>::infinity());
        std::vector<Eigen::Vector2f> hit_uv(depth.size());
        for (std::size_t t = 0; t < triangles; ++t) {
          const Box& box = boxes[t];
          if (box.y1 < rows.begin() || box.y0 >= rows.end() || box.x0 > box.x1) continue;
          const Eigen::Vector3d p0 = model.positions[3 * t].cast<double>();
          const Eigen::Vector3d e1 = model.positions[3 * t + 1].cast<double>() - p0;
          const Eigen::Vector3d e2 = model.positions[3 * t + 2].cast<double>() - p0;
          const Eigen::Vector3d normal = e1.cross(e2);
          for (int y = std::max(box.y0, rows.begin()); y <= std::min(box.y1, rows.end() - 1); ++y)
            for (int x = box.x0; x <= box.x1; ++x) {
              const Eigen::Vector3d dir = camera.pixel_direction(x, y);
              const double facing = normal.dot(dir);
              if (facing == 0.0 || (options.cull_back_faces && facing > 0.0)) continue;
              // Moller-Trumbore.
              const Eigen::Vector3d p = dir.cross(e2);
              const double det = e1.dot(p);
              if (det == 0.0) continue;
              const Eigen::Vector3d s = eye - p0;
              const double u = s.dot(p) / det;
              if (u < 0.0 || u > 1.0) continue;
              const Eigen::Vector3d q = s.cross(e1);
              const double v = dir.dot(q) / det;
              if (v < 0.0 || u + v > 1.0) continue;
              const double distance = e2.dot(q) / det;
              const double view_depth = distance * dir.dot(forward);
              if (view_depth < camera.near_plane || view_depth > camera.far_plane) continue;
              const std::size_t at =
                  std::size_t(y - rows.begin()) * std::size_t(width) + std::size_t(x);
              if (!(distance < depth[at])) continue;
              depth[at] = distance;
              hit_uv[at] =
                  ((1.0 - u - v) * model.uv[3 * t].cast<double>() +
                   u * model.uv[3 * t + 1].cast<double>() + v * model.uv[3 * t + 2].cast<double>())
                      .cast<float>();
            }
        }
        for (int y = rows.begin(); y < rows.end(); ++y)
          for (int x = 0; x < width; ++x) {
            const std::size_t at =
                std::size_t(y - rows.begin()) * std::size_t(width) + std::size_t(x);
            float* out = image.pixel(x, y);
            if (std::isinf(depth[at])) {
              out[0] = options.background.x();
              out[1] = options.background.y();
              out[2] = options.background.z();
              out[3] = 0.f;
              continue;
            }
            const Eigen::Vector3f c =
                options.texel_directions
                    ? slf_radiance_toward(model, hit_uv[at], eye)
                    : slf_radiance(model, hit_uv[at], -camera.pixel_direction(x, y));
            out[0] = c.x();
            out[1] = c.y();
            out[2] = c.z();
            out[3] = 1.f;
          }
      });
  return image;
}

}  // namespace render
