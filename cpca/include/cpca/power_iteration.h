// cpca/power_iteration.h: the first k principal components of one cluster's data.
//
// SLF paper (Miandji, Kronander & Unger), Appendix, Algorithm 1: power iteration with
// deflation on the n x n covariance F^T F, or, when the cluster has fewer points than
// dimensions (m < n), on the m x m Gram matrix F F^T, whose eigenvectors are the left
// singular vectors u; the principal directions are then v = F^T u / sigma. An iteration
// stops when the change of the normalised iterate falls below `tolerance` or, once below
// 1e-6, starts to grow (numerical fluctuation), or after `max_iterations` (the paper: 1e-12
// and 1000).
// Differences from the paper's listing, on purpose: the iterate is renormalised every step,
// the deflation is applied to A (A <- A - lambda v v^T, equivalent to deflating F for a
// symmetric A and much cheaper than recomputing F^T F), and the kappa rescaling that
// balances U and V for the SLF storage format is left out: CPCA wants orthonormal bases and
// weights that are plain projections onto them.
#pragma once

#include <Eigen/Core>

#include <cstdint>

namespace cpca {

using RowMatrixXf = Eigen::Matrix<float, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;

struct PowerIterationOptions {
  double tolerance = 1e-12;
  int max_iterations = 1000;
  std::uint64_t seed = 1;  // of the start vectors; the result is deterministic
  // Optional warm start: k x n directions (a previous fit of nearly the same points). Row p
  // starts component p (on the Gram path projected onto the points, F b_p, the left singular
  // vector it would give); a zero or vanishing start falls back to the seeded random one.
  // A search that refits clusters after moving a few points converges in a fraction of the
  // iterations from here.
  const Eigen::MatrixXd* start = nullptr;
};

struct PcaResult {
  // k x n, rows orthonormal: the principal directions in decreasing order of eigenvalue.
  // Directions past the data's rank (eigenvalue ~0) are zero rows with zero eigenvalue.
  Eigen::MatrixXd basis;
  Eigen::VectorXd eigenvalues;  // of F^T F (squared singular values), decreasing
  int iterations = 0;           // total over all components
  bool gram = false;            // the m < n path was taken
};

// `centred`: m x n, one point per row, mean already subtracted. Requires k >= 1 and
// k <= min(m, n) (throws std::invalid_argument otherwise).
PcaResult power_iteration_pca(const Eigen::Ref<const Eigen::MatrixXd>& centred, int k,
                              const PowerIterationOptions& options = {});

// The same from F F^T already formed (m x m, m < n; only the lower triangle is read), for a
// caller that keeps it up to date as points join and leave a cluster: the PCA then costs
// O(m n k) for the warm start and the directions instead of O(m^2 n) for the product. With a
// full warm start (k rows) it iterates the whole k-dimensional subspace at once
// (simultaneous iteration, Rutishauser 1970) until the captured energy trace(Q^T A Q) changes
// by less than `tolerance` (relative), then orders the directions by Rayleigh-Ritz: a refit
// needs the subspace, and per-direction convergence is slow when eigenvalues nearly tie.
PcaResult power_iteration_pca_gram(const Eigen::Ref<const Eigen::MatrixXd>& centred,
                                   Eigen::MatrixXd gram, int k,
                                   const PowerIterationOptions& options = {});

// The same result from Eigen's SelfAdjointEigenSolver (on the Gram matrix when m < n, as
// above): the oracle for tests and the `--pca eigen` option. Directions past the data's rank
// (eigenvalue below 1e-12 of the largest) are zero rows, as in power_iteration_pca.
PcaResult eigen_pca(const Eigen::Ref<const Eigen::MatrixXd>& centred, int k);

}  // namespace cpca
