// Power-iteration PCA against Eigen's eigen-solver and against closed forms (a spectrum we
// build), in both shapes: fewer points than dimensions (Gram path) and more.
#include "cpca/power_iteration.h"

#include "cpca_test_support.h"

#include <gtest/gtest.h>
#include <Eigen/QR>

#include <cmath>
#include <string>

namespace {

using cpca_test::with_spectrum;

Eigen::VectorXd decaying(int r) {
  Eigen::VectorXd s(r);
  for (int i = 0; i < r; ++i) s[i] = 10.0 * std::pow(0.7, i);  // eigenvalue ratio 0.49
  return s;
}

struct Shape {
  int m, n;
};

class PowerIterationShapes : public ::testing::TestWithParam<Shape> {};

TEST_P(PowerIterationShapes, MatchesEigenSolver) {
  const Shape shape = GetParam();
  const int k = 8;
  const Eigen::MatrixXd f = with_spectrum(shape.m, shape.n, decaying(20), 7);
  const cpca::PcaResult pi = cpca::power_iteration_pca(f, k);
  const cpca::PcaResult oracle = cpca::eigen_pca(f, k);
  EXPECT_EQ(pi.gram, shape.m < shape.n);
  for (int p = 0; p < k; ++p) {
    // Eigenvalues within 1e-4 relative (the bound we hold it to; measured ~1e-12 with these gaps).
    EXPECT_NEAR(pi.eigenvalues[p], oracle.eigenvalues[p], 1e-4 * oracle.eigenvalues[p]);
    EXPECT_NEAR(pi.eigenvalues[p], std::pow(10.0 * std::pow(0.7, p), 2), 1e-6 * pi.eigenvalues[p]);
    // Same direction up to sign.
    EXPECT_GT(std::abs(pi.basis.row(p).dot(oracle.basis.row(p))), 1 - 1e-8) << "component " << p;
  }
  // Orthonormal rows.
  EXPECT_LT(
      (pi.basis * pi.basis.transpose() - Eigen::MatrixXd::Identity(k, k)).cwiseAbs().maxCoeff(),
      1e-8);
  // Eckart-Young: the residual of projecting onto k components is the rest of the spectrum.
  const Eigen::MatrixXd residual = f - f * pi.basis.transpose() * pi.basis;
  double rest = 0;
  for (int i = k; i < 20; ++i) rest += std::pow(10.0 * std::pow(0.7, i), 2);
  EXPECT_NEAR(residual.squaredNorm(), rest, 1e-8 * f.squaredNorm());
}

// Named "40x120" etc., so CTest lists the shape rather than the parameter's bytes.
INSTANTIATE_TEST_SUITE_P(BothShapes, PowerIterationShapes,
                         ::testing::Values(Shape{40, 120}, Shape{300, 60}, Shape{60, 60}),
                         [](const ::testing::TestParamInfo<Shape>& p) {
                           return std::to_string(p.param.m) + "x" + std::to_string(p.param.n);
                         });

// A warm start from the fit of slightly different points (as after a search moved a few)
// reaches the oracle's spectrum in both shapes, in fewer iterations than the seeded start.
TEST_P(PowerIterationShapes, WarmStartConverges) {
  const Shape shape = GetParam();
  const int k = 8;
  const Eigen::MatrixXd f = with_spectrum(shape.m, shape.n, decaying(20), 7);
  std::srand(9);
  const Eigen::MatrixXd moved = f + 1e-3 * Eigen::MatrixXd::Random(shape.m, shape.n);
  const cpca::PcaResult previous = cpca::power_iteration_pca(moved, k);
  cpca::PowerIterationOptions warm;
  warm.start = &previous.basis;
  const cpca::PcaResult pi = cpca::power_iteration_pca(f, k, warm);
  const cpca::PcaResult cold = cpca::power_iteration_pca(f, k);
  const cpca::PcaResult oracle = cpca::eigen_pca(f, k);
  for (int p = 0; p < k; ++p) {
    EXPECT_NEAR(pi.eigenvalues[p], oracle.eigenvalues[p], 1e-6 * oracle.eigenvalues[p]);
    EXPECT_GT(std::abs(pi.basis.row(p).dot(oracle.basis.row(p))), 1 - 1e-8) << "component " << p;
  }
  EXPECT_LT(pi.iterations, cold.iterations);
}

TEST(PowerIteration, RankDeficientDataGivesZeroComponents) {
  Eigen::VectorXd s(3);
  s << 3, 2, 1;
  const Eigen::MatrixXd f = with_spectrum(30, 50, s, 3);
  const cpca::PcaResult pi = cpca::power_iteration_pca(f, 5);
  EXPECT_NEAR(pi.eigenvalues[2], 1.0, 1e-9);
  EXPECT_EQ(pi.eigenvalues[3], 0.0);
  EXPECT_EQ(pi.eigenvalues[4], 0.0);
  EXPECT_EQ(pi.basis.row(4).norm(), 0.0);
  EXPECT_NEAR((f - f * pi.basis.transpose() * pi.basis).norm(), 0.0, 1e-9);
}

TEST(PowerIteration, ZeroDataAndDeterminism) {
  const cpca::PcaResult zero = cpca::power_iteration_pca(Eigen::MatrixXd::Zero(5, 4), 2);
  EXPECT_EQ(zero.eigenvalues.norm(), 0.0);
  const Eigen::MatrixXd f = with_spectrum(20, 30, decaying(10), 11);
  const cpca::PcaResult a = cpca::power_iteration_pca(f, 4), b = cpca::power_iteration_pca(f, 4);
  EXPECT_EQ(a.basis, b.basis);
  EXPECT_THROW(cpca::power_iteration_pca(f, 0), std::invalid_argument);
  EXPECT_THROW(cpca::power_iteration_pca(f, 21), std::invalid_argument);
}

}  // namespace
