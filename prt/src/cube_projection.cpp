#include "prt/cube_projection.h"

#include "prt/sh.h"

#include <vector>

namespace prt {

ShLighting project_cube(const probes::CubeMap& cube, int order) {
  check_order(order, "projection order");
  const int n = sh_count(order), size = cube.size();
  // Solid angles are the same on every face.
  std::vector<double> solid_angle(std::size_t(size) * std::size_t(size));
  for (int y = 0; y < size; ++y) {
    for (int x = 0; x < size; ++x) {
      solid_angle[std::size_t(y) * std::size_t(size) + std::size_t(x)] =
          cube.texel_solid_angle(x, y);
    }
  }
  ShLighting total = ShLighting::Zero(n, 3);
  Eigen::Matrix3Xd directions(3, size);
  ShBatchD basis(n, size);
  Eigen::Matrix<double, Eigen::Dynamic, 3> weighted(size, 3);
  for (int face = 0; face < probes::kCubeFaces; ++face) {
    for (int y = 0; y < size; ++y) {
      for (int x = 0; x < size; ++x) {
        directions.col(x) = cube.texel_direction(face, x, y);
        weighted.row(x) = cube.texel(face, x, y).cast<double>().transpose() *
                          solid_angle[std::size_t(y) * std::size_t(size) + std::size_t(x)];
      }
      sh_eval_batch(order, directions, basis);
      total.noalias() += basis * weighted;
    }
  }
  return total;
}

}  // namespace prt
