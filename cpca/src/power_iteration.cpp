// Modified power iteration (SLF paper, Appendix, Algorithm 1); see the header for the
// deliberate differences from the printed listing.
#include "cpca/power_iteration.h"

#include "splitmix.h"

#include <Eigen/Eigenvalues>
#include <Eigen/QR>

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

namespace cpca {
namespace {

void check_k(const Eigen::Ref<const Eigen::MatrixXd>& f, int k) {
  if (k < 1 || k > std::min(f.rows(), f.cols())) {
    throw std::invalid_argument(
        "PCA: component count must be in [1, min(points, dimension)] = [1, " +
        std::to_string(std::min(f.rows(), f.cols())) + "], got " + std::to_string(k));
  }
}

using detail::next_uniform;

// Column p of `directions` made orthogonal to columns 0..p-1 (orthonormal already), twice for
// stability, and normalised; false when less than 1e-6 x `expected` of its norm is left. The
// directions are columns, not the basis's rows, so each dot product reads contiguous memory:
// on the basis's strided rows these loops were a third of a small cluster's refit.
bool orthonormalise(Eigen::MatrixXd& directions, int p, double expected) {
  auto direction = directions.col(p);
  for (int pass = 0; pass < 2; ++pass)
    for (int q = 0; q < p; ++q) direction -= direction.dot(directions.col(q)) * directions.col(q);
  const double norm = direction.norm();
  if (!(norm > 1e-6 * expected)) return false;
  direction /= norm;
  return true;
}

// Power iteration with deflation on A (lower triangle read and deflated), the smaller of F^T F
// and F F^T.
PcaResult iterate(const Eigen::Ref<const Eigen::MatrixXd>& f, Eigen::MatrixXd& a, int k,
                  const PowerIterationOptions& options) {
  const Eigen::Index m = f.rows(), n = f.cols();
  PcaResult result;
  result.gram = m < n;
  result.basis = Eigen::MatrixXd::Zero(k, n);
  result.eigenvalues = Eigen::VectorXd::Zero(k);
  const double scale = a.trace();
  if (!(scale > 0.0)) return result;  // all points equal the mean: nothing to find
  std::uint64_t state = options.seed;
  Eigen::VectorXd v(a.rows()), next(a.rows());
  Eigen::MatrixXd directions(n, k);
  int found = 0;
  for (int p = 0; p < k; ++p) {
    for (Eigen::Index i = 0; i < v.size(); ++i) v[i] = next_uniform(state) - 0.5;
    v.normalize();
    if (options.start && p < options.start->rows() && options.start->cols() == n) {
      Eigen::VectorXd warm = result.gram ? Eigen::VectorXd(f * options.start->row(p).transpose())
                                         : Eigen::VectorXd(options.start->row(p).transpose());
      if (const double norm = warm.norm(); norm > 1e-9 * std::sqrt(scale)) v = warm / norm;
    }
    double lambda = 0.0, previous_change = std::numeric_limits<double>::infinity();
    for (int it = 0; it < options.max_iterations; ++it) {
      ++result.iterations;
      next.noalias() = a.selfadjointView<Eigen::Lower>() * v;
      lambda = next.norm();
      if (!(lambda > 1e-12 * scale)) {  // the remaining spectrum is rounding noise
        lambda = 0.0;
        break;
      }
      next /= lambda;
      const double change = (next - v).norm();
      v.swap(next);
      // Growth of the change means rounding noise only once it is already small; early on
      // the change can grow while the iterate turns toward the dominant direction.
      if (change < options.tolerance || (change > previous_change && change < 1e-6)) break;
      previous_change = change;
    }
    if (lambda == 0.0) break;  // rows p..k-1 stay zero
    result.eigenvalues[p] = lambda;
    a.selfadjointView<Eigen::Lower>().rankUpdate(v, -lambda);
    // v is a left singular vector u on the Gram path; the principal direction is F^T u /
    // sigma. Orthogonalising against the earlier directions (twice, for stability) and
    // renormalising keeps the basis orthonormal even for eigenvalues near the noise floor,
    // where dividing by sigma would amplify rounding.
    auto direction = directions.col(p);
    if (result.gram)
      direction.noalias() = f.transpose() * v;
    else
      direction = v;
    const double expected = result.gram ? std::sqrt(lambda) : 1.0;
    if (!orthonormalise(directions, p, expected)) {  // nothing left but rounding noise
      result.eigenvalues[p] = 0.0;
      break;
    }
    found = p + 1;
  }
  result.basis.topRows(found) = directions.leftCols(found).transpose();
  return result;
}

}  // namespace

PcaResult power_iteration_pca(const Eigen::Ref<const Eigen::MatrixXd>& f, int k,
                              const PowerIterationOptions& options) {
  check_k(f, k);
  const Eigen::Index m = f.rows(), n = f.cols();
  // A is the smaller of F^T F (n x n) and F F^T (m x m); both share the non-zero spectrum.
  // Only its lower triangle is formed and read: a rank update costs half the product, and
  // the symmetric matrix-vector product reads A once for both triangles. On a cluster larger
  // than the dimension these two are nearly all of the PCA's time.
  Eigen::MatrixXd a = Eigen::MatrixXd::Zero(std::min(m, n), std::min(m, n));
  if (m < n)
    a.selfadjointView<Eigen::Lower>().rankUpdate(f);
  else
    a.selfadjointView<Eigen::Lower>().rankUpdate(f.transpose());
  return iterate(f, a, k, options);
}

PcaResult power_iteration_pca_gram(const Eigen::Ref<const Eigen::MatrixXd>& f, Eigen::MatrixXd gram,
                                   int k, const PowerIterationOptions& options) {
  check_k(f, k);
  if (!(f.rows() < f.cols()) || gram.rows() != f.rows() || gram.cols() != f.rows())
    throw std::invalid_argument("PCA: a Gram matrix needs fewer points than dimensions and " +
                                std::to_string(f.rows()) + " x " + std::to_string(f.rows()) +
                                " entries, got " + std::to_string(gram.rows()) + " x " +
                                std::to_string(gram.cols()));
  if (!options.start || options.start->rows() != k || options.start->cols() != f.cols())
    return iterate(f, gram, k, options);
  gram = gram.selfadjointView<Eigen::Lower>();  // the caller may have filled one triangle
  const Eigen::Index m = f.rows(), n = f.cols();
  PcaResult result;
  result.gram = true;
  result.basis = Eigen::MatrixXd::Zero(k, n);
  result.eigenvalues = Eigen::VectorXd::Zero(k);
  const double scale = gram.trace();
  if (!(scale > 0.0)) return result;
  // Simultaneous iteration (Rutishauser 1970) from the previous directions projected onto
  // the points; a vanishing start column gets a seeded random one.
  Eigen::MatrixXd q = f * options.start->transpose();
  std::uint64_t state = options.seed;
  for (int p = 0; p < k; ++p)
    if (!(q.col(p).norm() > 1e-9 * std::sqrt(scale)))
      for (Eigen::Index i = 0; i < m; ++i) q(i, p) = next_uniform(state) - 0.5;
  const auto orthonormal = [k](const Eigen::MatrixXd& z) {
    return Eigen::MatrixXd(Eigen::HouseholderQR<Eigen::MatrixXd>(z).householderQ() *
                           Eigen::MatrixXd::Identity(z.rows(), k));
  };
  q = orthonormal(q);
  Eigen::MatrixXd z = gram * q;
  double energy = (q.transpose() * z).trace();
  for (int it = 0; it < options.max_iterations; ++it) {
    ++result.iterations;
    q = orthonormal(z);
    z.noalias() = gram * q;
    const double next = (q.transpose() * z).trace();
    const bool settled = !(next - energy > options.tolerance * next);
    energy = next;
    if (settled) break;
  }
  // Rayleigh-Ritz: the directions within the subspace, by decreasing eigenvalue.
  Eigen::MatrixXd h = q.transpose() * z;
  h = 0.5 * (h + h.transpose()).eval();
  const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> ritz(h);
  if (ritz.info() != Eigen::Success) return iterate(f, gram, k, options);
  // Every direction F^T u in one product, by decreasing eigenvalue.
  Eigen::MatrixXd directions = f.transpose() * (q * ritz.eigenvectors().rowwise().reverse());
  int found = 0;
  for (int p = 0; p < k; ++p) {
    const double lambda = ritz.eigenvalues()[k - 1 - p];
    if (!(lambda > 1e-12 * scale) || !orthonormalise(directions, p, std::sqrt(lambda))) break;
    result.eigenvalues[p] = lambda;
    found = p + 1;
  }
  result.basis.topRows(found) = directions.leftCols(found).transpose();
  return result;
}

PcaResult eigen_pca(const Eigen::Ref<const Eigen::MatrixXd>& f, int k) {
  check_k(f, k);
  PcaResult result;
  // Like the power iteration, work on the smaller of F^T F and F F^T: a full eigensolve of
  // the n x n covariance costs O(n^3) per cluster (minutes on the bunny at n = 1296).
  result.gram = f.rows() < f.cols();
  const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> solver(
      result.gram ? Eigen::MatrixXd(f * f.transpose()) : Eigen::MatrixXd(f.transpose() * f));
  if (solver.info() != Eigen::Success) throw std::runtime_error("PCA: eigen-solver failed");
  result.basis = Eigen::MatrixXd::Zero(k, f.cols());
  result.eigenvalues = Eigen::VectorXd::Zero(k);
  const Eigen::Index size = solver.eigenvalues().size();
  const double scale = std::max(0.0, solver.eigenvalues()[size - 1]);
  for (int p = 0; p < k; ++p) {  // eigenvalues come in increasing order
    const double lambda = std::max(0.0, solver.eigenvalues()[size - 1 - p]);
    if (!(lambda > 1e-12 * scale)) break;  // rank reached: the remaining rows stay zero
    result.eigenvalues[p] = lambda;
    if (result.gram) {
      // Left singular vector u -> principal direction F^T u / sigma, renormalised.
      const Eigen::VectorXd v = f.transpose() * solver.eigenvectors().col(size - 1 - p);
      result.basis.row(p) = v.normalized().transpose();
    } else {
      result.basis.row(p) = solver.eigenvectors().col(size - 1 - p).transpose();
    }
  }
  return result;
}

}  // namespace cpca
