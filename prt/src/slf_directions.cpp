#include "prt/slf_directions.h"

#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

namespace prt {

void SlfGrid::validate() const {
  auto check = [](int value, const char* name) {
    if (value < 1 || value > 4096)
      throw std::invalid_argument(std::string("the surface light field's ") + name +
                                  " directions must be between 1 and 4096, not " +
                                  std::to_string(value));
  };
  check(azimuth, "azimuth");
  check(elevation, "elevation");
}

Eigen::Vector3d slf_direction(double xi1, double xi2) {
  const double theta = M_PI * (xi1 - 1.0), phi = M_PI * xi2;
  return {std::sin(phi) * std::sin(theta), std::cos(phi), -std::sin(phi) * std::cos(theta)};
}

Eigen::Vector3d slf_direction_at_cosine(double xi1, double cos_polar) {
  const double theta = M_PI * (xi1 - 1.0);
  const double sin_polar = std::sqrt(std::max(0.0, 1.0 - cos_polar * cos_polar));
  return {sin_polar * std::sin(theta), cos_polar, -sin_polar * std::cos(theta)};
}

Eigen::Vector2d slf_coordinates(const Eigen::Vector3d& direction) {
  const double n = direction.norm();
  if (!(n > 0.0)) return {1.0, 0.5};
  const double y = std::clamp(direction.y() / n, -1.0, 1.0);
  return {1.0 + std::atan2(direction.x(), -direction.z()) / M_PI, std::acos(y) / M_PI};
}

bool slf_grid_uses_normals(const SlfGrid& grid) {
  return grid.space != SlfDirectionSpace::kView;
}

double slf_polar_span(const SlfGrid& grid) {
  return grid.space == SlfDirectionSpace::kLocal ? 0.5 * M_PI : M_PI;
}

Eigen::Vector3d slf_grid_direction(const SlfGrid& grid, int column) {
  const int i = column % grid.azimuth, j = column / grid.azimuth;
  return slf_direction(2.0 * (i + 0.5) / grid.azimuth,
                       (j + 0.5) / grid.elevation * slf_polar_span(grid) / M_PI);
}

Eigen::Matrix3d slf_local_frame(const Eigen::Vector3d& normal) {
  // The renderers' shaders repeat this rule in float (render/slf_renderer.cpp); the threshold
  // only decides texels whose normal is vertical to float precision.
  Eigen::Vector3d tangent = Eigen::Vector3d::UnitY() - normal.y() * normal;
  if (tangent.squaredNorm() < 1e-8)
    tangent = -Eigen::Vector3d::UnitZ() - normal.dot(-Eigen::Vector3d::UnitZ()) * normal;
  tangent.normalize();
  Eigen::Matrix3d frame;
  frame.col(0) = tangent;
  frame.col(1) = tangent.cross(normal);
  frame.col(2) = normal;
  return frame;
}

SlfPointSpace::SlfPointSpace(const SlfGrid& grid, const Eigen::Vector3d& normal)
    : space_(grid.space), normal_(normal), frame_(Eigen::Matrix3d::Identity()) {
  if (space_ == SlfDirectionSpace::kLocal) frame_ = slf_local_frame(normal);
}

// Eq. 1's axes put the pole on +Y and azimuth 0 on -Z; the local grid's are the normal and
// the tangent, so a local direction is (bitangent, normal, -tangent) components.
Eigen::Vector3d SlfPointSpace::to_grid(const Eigen::Vector3d& view) const {
  switch (space_) {
    case SlfDirectionSpace::kView:
      return view;
    case SlfDirectionSpace::kReflected:
      return 2.0 * normal_.dot(view) * normal_ - view;
    case SlfDirectionSpace::kLocal:
      return {frame_.col(1).dot(view), frame_.col(2).dot(view), -frame_.col(0).dot(view)};
  }
  return view;
}

Eigen::Vector3d SlfPointSpace::to_view(const Eigen::Vector3d& grid_direction) const {
  if (space_ != SlfDirectionSpace::kLocal) return to_grid(grid_direction);  // its own inverse
  return grid_direction.x() * frame_.col(1) + grid_direction.y() * frame_.col(2) -
         grid_direction.z() * frame_.col(0);
}

Eigen::Vector3d slf_grid_space(const SlfGrid& grid, const Eigen::Vector3d& view,
                               const Eigen::Vector3d& normal) {
  return SlfPointSpace(grid, normal).to_grid(view);
}

Eigen::Vector3d slf_grid_view(const SlfGrid& grid, const Eigen::Vector3d& grid_direction,
                              const Eigen::Vector3d& normal) {
  return SlfPointSpace(grid, normal).to_view(grid_direction);
}

Eigen::Vector2d slf_grid_coordinates(const SlfGrid& grid, const Eigen::Vector3d& grid_direction) {
  const Eigen::Vector2d xi = slf_coordinates(grid_direction);
  return {xi.x(), std::min(1.0, xi.y() * M_PI / slf_polar_span(grid))};
}

}  // namespace prt
