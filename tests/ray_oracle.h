// tests/ray_oracle.h: the brute-force ray test that bake tests count visibility with,
// independent of Embree and of the baker's origin logic.
#pragma once

#include "meshes/mesh.h"

#include <Eigen/Core>
#include <cmath>
#include <cstddef>

namespace test_support {

// Moller-Trumbore in double: does o + t d hit triangle `index` of `m` at some t > tmin?
inline bool ray_hits_triangle(const meshes::Mesh& m, std::size_t index, const Eigen::Vector3d& o,
                              const Eigen::Vector3d& d, double tmin) {
  const meshes::Triangle& tri = m.triangles[index];
  const Eigen::Vector3d p0 = m.positions[tri[0]].cast<double>();
  const Eigen::Vector3d e1 = m.positions[tri[1]].cast<double>() - p0;
  const Eigen::Vector3d e2 = m.positions[tri[2]].cast<double>() - p0;
  const Eigen::Vector3d pv = d.cross(e2);
  const double det = e1.dot(pv);
  if (std::abs(det) < 1e-14) return false;
  const Eigen::Vector3d tv = o - p0;
  const double u = tv.dot(pv) / det;
  if (u < 0 || u > 1) return false;
  const Eigen::Vector3d qv = tv.cross(e1);
  const double v = d.dot(qv) / det;
  if (v < 0 || u + v > 1) return false;
  return e2.dot(qv) / det > tmin;
}

}  // namespace test_support
