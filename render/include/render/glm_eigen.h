// render/glm_eigen.h: the one crossing between Eigen (numerics: bake, compression, rotation)
// and GLM (GL-side math: camera matrices, the vectors handed to shaders), column-major on
// both sides so a matrix crosses element for element.
#pragma once

#include <Eigen/Core>
#include <glm/glm.hpp>

namespace render {

inline glm::dvec3 to_glm(const Eigen::Vector3d& v) {
  return {v.x(), v.y(), v.z()};
}

inline Eigen::Vector3d to_eigen(const glm::dvec3& v) {
  return {v.x, v.y, v.z};
}

inline Eigen::Matrix4d to_eigen(const glm::dmat4& m) {
  Eigen::Matrix4d out;
  for (int c = 0; c < 4; ++c)
    for (int r = 0; r < 4; ++r) out(r, c) = m[c][r];  // glm indexes [column][row]
  return out;
}

inline glm::dmat3 to_glm(const Eigen::Matrix3d& m) {
  glm::dmat3 out;
  for (int c = 0; c < 3; ++c)
    for (int r = 0; r < 3; ++r) out[c][r] = m(r, c);
  return out;
}

inline glm::dmat4 to_glm(const Eigen::Matrix4d& m) {
  glm::dmat4 out;
  for (int c = 0; c < 4; ++c)
    for (int r = 0; r < 4; ++r) out[c][r] = m(r, c);
  return out;
}

}  // namespace render
