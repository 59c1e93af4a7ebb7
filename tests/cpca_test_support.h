// tests/cpca_test_support.h: geometry and data shared by the cpca suites.
#pragma once

#include "cpca/geometry.h"

#include <Eigen/Core>
#include <Eigen/QR>

#include <cstdlib>

namespace cpca_test {

// A regular n x n vertex grid on the unit square (z = 0), two triangles per cell.
inline cpca::Geometry grid(int n) {
  cpca::Geometry g;
  for (int y = 0; y < n; ++y)
    for (int x = 0; x < n; ++x)
      g.positions.emplace_back(float(x) / float(n - 1), float(y) / float(n - 1), 0.f);
  for (int y = 0; y + 1 < n; ++y)
    for (int x = 0; x + 1 < n; ++x) {
      const std::uint32_t a = std::uint32_t(y * n + x), b = a + 1, c = a + std::uint32_t(n),
                          d = c + 1;
      g.triangles.push_back({a, b, d});
      g.triangles.push_back({a, d, c});
    }
  return g;
}

// m x n data with singular values s (r = s.size()) along random orthonormal directions.
inline Eigen::MatrixXd with_spectrum(int m, int n, const Eigen::VectorXd& s, unsigned seed) {
  std::srand(seed);
  const int r = int(s.size());
  const Eigen::MatrixXd u =
      Eigen::HouseholderQR<Eigen::MatrixXd>(Eigen::MatrixXd::Random(m, r)).householderQ() *
      Eigen::MatrixXd::Identity(m, r);
  const Eigen::MatrixXd v =
      Eigen::HouseholderQR<Eigen::MatrixXd>(Eigen::MatrixXd::Random(n, r)).householderQ() *
      Eigen::MatrixXd::Identity(n, r);
  return u * s.asDiagonal() * v.transpose();
}

}  // namespace cpca_test
