// The view-side fits of prt/view_fit.h. Each is a linear map applied to the hemisphere
// quadrature of the view integral, so brdf_matrix keeps one product quadrature for all.
#include "prt/view_fit.h"

#include "prt/sh.h"

#include <Eigen/Cholesky>

#include <cmath>
#include <stdexcept>
#include <string>

namespace prt {
namespace {

// HSH's direction: cos theta' = 2 z - 1 and the tangent part scaled by sin theta' / sin theta,
// which is sqrt(4 z / (1 + z)) in closed form (no division by sin theta at the pole).
Eigen::Vector3d hsh_direction(const Eigen::Vector3d& v) {
  const double z = std::max(0.0, v.z());
  const double scale = std::sqrt(4.0 * z / (1.0 + z));
  return {scale * v.x(), scale * v.y(), 2.0 * z - 1.0};
}

}  // namespace

bool view_fit_renderable(ViewFit fit) {
  return fit == ViewFit::kHemisphere || fit == ViewFit::kEven || fit == ViewFit::kLeastSquares;
}

void view_basis_eval(ViewFit fit, int order, const Eigen::Vector3d& v, double* out) {
  if (fit != ViewFit::kHemisphericalHarmonics) {
    sh_eval(order, v, out);
    return;
  }
  sh_eval(order, hsh_direction(v), out);
  const int n = sh_count(order);
  for (int i = 0; i < n; ++i) out[i] *= std::sqrt(2.0);
}

Eigen::MatrixXd view_projection(ViewFit fit, int order, const Eigen::Matrix3Xd& directions,
                                const Eigen::VectorXd& weights, double lambda) {
  check_order(order, "view fit order");
  if (directions.cols() != weights.size()) {
    throw std::invalid_argument("view_projection: one weight per direction");
  }
  if (!(lambda > 0.0 && lambda <= 1.0) && fit == ViewFit::kLeastSquares) {
    throw std::invalid_argument("view fit lambda must be in (0, 1], got " + std::to_string(lambda));
  }
  const int n = sh_count(order);
  // The view basis at every node, by the batched SH evaluation (HSH: at remapped nodes).
  ShBatchD batch;
  if (fit == ViewFit::kHemisphericalHarmonics) {
    Eigen::Matrix3Xd remapped(3, directions.cols());
    for (Eigen::Index k = 0; k < directions.cols(); ++k)
      remapped.col(k) = hsh_direction(directions.col(k));
    sh_eval_batch(order, remapped, batch);
    batch *= std::sqrt(2.0);
  } else {
    sh_eval_batch(order, directions, batch);
  }
  const Eigen::MatrixXd y = batch;
  Eigen::MatrixXd projection = y * weights.asDiagonal();  // int_{v.z>0} basis_i (.)
  switch (fit) {
    case ViewFit::kHemisphere:
    case ViewFit::kHemisphericalHarmonics:  // orthonormal on the hemisphere: a plain projection
      return projection;
    case ViewFit::kEven:
      // The mirror image adds (-1)^(l+m) times the upper integral: 2x for l + m even, else 0.
      for (int l = 0; l < order; ++l) {
        for (int m = -l; m <= l; ++m) {
          projection.row(sh_index(l, m)) *= ((l + m) % 2 == 0) ? 2.0 : 0.0;
        }
      }
      return projection;
    case ViewFit::kLeastSquares: {
      // Normal equations of the penalised fit: (G + lambda L) B = B_hemisphere. G is
      // positive definite (no polynomial vanishes on an open set) and L semi-definite, so
      // Cholesky applies; L lifts G's small eigenvalues, whose functions live below the
      // horizon and so have l >= 1.
      Eigen::MatrixXd system = projection * y.transpose();
      for (int i = 0; i < n; ++i) {
        const int l = sh_band(i);
        system(i, i) += lambda * l * (l + 1);
      }
      return system.llt().solve(projection);
    }
  }
  throw std::invalid_argument("unknown view fit");
}

}  // namespace prt
