#include "prt/slf_directions.h"

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

Eigen::Vector2d slf_coordinates(const Eigen::Vector3d& direction) {
  const double n = direction.norm();
  if (!(n > 0.0)) return {1.0, 0.5};
  const double y = std::clamp(direction.y() / n, -1.0, 1.0);
  return {1.0 + std::atan2(direction.x(), -direction.z()) / M_PI, std::acos(y) / M_PI};
}

Eigen::Vector3d slf_grid_direction(const SlfGrid& grid, int column) {
  const int i = column % grid.azimuth, j = column / grid.azimuth;
  return slf_direction(2.0 * (i + 0.5) / grid.azimuth, (j + 0.5) / grid.elevation);
}

Eigen::Vector3d slf_grid_space(const SlfGrid& grid, const Eigen::Vector3d& view,
                               const Eigen::Vector3d& normal) {
  if (grid.space == SlfDirectionSpace::kView) return view;
  return 2.0 * normal.dot(view) * normal - view;
}

}  // namespace prt
