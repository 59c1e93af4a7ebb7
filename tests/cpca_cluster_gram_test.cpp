// The Gram matrices a search keeps per cluster (cpca/cluster_gram.h) against the product
// formed from scratch, and the warm subspace iteration on them (power_iteration.h) against
// Eigen's eigen-solver.
#include "cpca/cluster_gram.h"
#include "cpca/cluster_pca.h"
#include "cpca/lbg.h"
#include "cpca/power_iteration.h"

#include "cpca_test_support.h"

#include <gtest/gtest.h>
#include <Eigen/Eigenvalues>
#include <Eigen/QR>

#include <cmath>
#include <random>
#include <vector>

namespace {

// m x n points with eigenvalues (of F F^T) near `lambda` along random orthonormal
// directions, centred.
Eigen::MatrixXd with_eigenvalues(int m, int n, const std::vector<double>& lambda, unsigned seed) {
  Eigen::VectorXd s(Eigen::Index(lambda.size()));
  for (std::size_t i = 0; i < lambda.size(); ++i) s[Eigen::Index(i)] = std::sqrt(lambda[i]);
  Eigen::MatrixXd f = cpca_test::with_spectrum(m, n, s, seed);
  f.rowwise() -= f.colwise().mean();
  return f;
}

// Nearly tied eigenvalues among the first k, where one direction at a time converges slowly.
std::vector<double> nearly_tied() {
  std::vector<double> lambda;
  for (int i = 0; i < 30; ++i)
    lambda.push_back(i < 8 ? 100.0 * (1 - 0.001 * i) : 10.0 * std::pow(0.8, i));
  return lambda;
}

double captured(const Eigen::MatrixXd& f, const Eigen::MatrixXd& basis) {
  return (f * basis.transpose()).squaredNorm();
}

TEST(PowerIterationGram, WarmSubspaceCapturesTheTopEigenvaluesDespiteNearTies) {
  const int k = 8;
  const Eigen::MatrixXd f = with_eigenvalues(60, 200, nearly_tied(), 3);
  const cpca::PcaResult oracle = cpca::eigen_pca(f, k);
  const double best = oracle.eigenvalues.sum();
  // Warm start: the oracle's directions turned away by noise of 0.3 per entry (relative).
  std::mt19937 rng(5);
  std::normal_distribution<double> noise(0, 0.3 / std::sqrt(200.0));
  Eigen::MatrixXd start = oracle.basis;
  for (Eigen::Index i = 0; i < start.size(); ++i) start(i) += noise(rng);
  cpca::PowerIterationOptions o;
  o.tolerance = 1e-10;
  o.start = &start;
  const cpca::PcaResult warm = cpca::power_iteration_pca_gram(f, f * f.transpose(), k, o);
  EXPECT_TRUE(warm.gram);
  EXPECT_NEAR(captured(f, warm.basis), best, 1e-8 * best);
  EXPECT_LT(
      (warm.basis * warm.basis.transpose() - Eigen::MatrixXd::Identity(k, k)).cwiseAbs().maxCoeff(),
      1e-10);
  for (int p = 0; p < k; ++p) {
    EXPECT_NEAR(warm.eigenvalues[p], oracle.eigenvalues[p], 1e-6 * oracle.eigenvalues[p]);
    if (p > 0) {
      EXPECT_GE(warm.eigenvalues[p - 1], warm.eigenvalues[p]);
    }
  }
  // The deflated iteration to the same tolerance needs many more products for these ties.
  o.start = nullptr;
  const cpca::PcaResult cold = cpca::power_iteration_pca(f, k, o);
  EXPECT_LT(warm.iterations * 4, cold.iterations);
}

TEST(PowerIterationGram, VanishingStartRowsAndNoStartStillConverge) {
  const int k = 8;  // the gap after the 8th eigenvalue is wide (nearly_tied)
  const Eigen::MatrixXd f = with_eigenvalues(40, 120, nearly_tied(), 9);
  const cpca::PcaResult oracle = cpca::eigen_pca(f, k);
  Eigen::MatrixXd start = oracle.basis;
  start.row(2).setZero();  // a previous basis past its cluster's rank
  start.row(7).setZero();
  cpca::PowerIterationOptions o;
  o.tolerance = 1e-12;
  o.start = &start;
  const cpca::PcaResult warm = cpca::power_iteration_pca_gram(f, f * f.transpose(), k, o);
  EXPECT_NEAR(captured(f, warm.basis), oracle.eigenvalues.sum(), 1e-8 * oracle.eigenvalues.sum());
  // Without a start it is the deflated iteration on the given matrix: the same as forming it.
  o.start = nullptr;
  const cpca::PcaResult given = cpca::power_iteration_pca_gram(f, f * f.transpose(), k, o);
  const cpca::PcaResult formed = cpca::power_iteration_pca(f, k, o);
  EXPECT_NEAR(captured(f, given.basis), captured(f, formed.basis),
              1e-9 * captured(f, formed.basis));
  EXPECT_THROW(cpca::power_iteration_pca_gram(f.transpose(), f.transpose() * f, k, o),
               std::invalid_argument);  // more points than dimensions
}

TEST(PowerIterationGram, RankBelowKLeavesZeroRows) {
  const Eigen::MatrixXd f = with_eigenvalues(30, 80, {50, 20, 5}, 4);
  Eigen::MatrixXd start = Eigen::MatrixXd::Random(6, 80);
  cpca::PowerIterationOptions o;
  o.tolerance = 1e-12;
  o.start = &start;
  const cpca::PcaResult r = cpca::power_iteration_pca_gram(f, f * f.transpose(), 6, o);
  // Rank 3 after centring: three directions hold all of it.
  EXPECT_NEAR(captured(f, r.basis), f.squaredNorm(), 1e-8 * f.squaredNorm());
  for (int p = 3; p < 6; ++p) EXPECT_EQ(r.basis.row(p).squaredNorm(), 0.0) << p;
}

// x_i . x_j in double of cluster c's members, formed from scratch.
Eigen::MatrixXd product(const cpca::DataMatrix& x, const std::vector<std::uint32_t>& members) {
  Eigen::MatrixXd rows(Eigen::Index(members.size()), x.cols());
  for (std::size_t i = 0; i < members.size(); ++i)
    rows.row(Eigen::Index(i)) = x.row(members[i]).cast<double>();
  return rows * rows.transpose();
}

TEST(ClusterGrams, EqualTheProductFromScratchAsPointsMove) {
  const int points = 300, dimension = 64, clusters = 8;
  std::mt19937 rng(11);
  std::uniform_real_distribution<float> value(-1, 1);
  cpca::DataMatrix x(points, dimension);
  for (Eigen::Index i = 0; i < x.size(); ++i) x.data()[i] = value(rng) + 3.0f;  // off-centre
  std::vector<std::uint32_t> cluster_of(points);
  for (int p = 0; p < points; ++p) cluster_of[std::size_t(p)] = std::uint32_t(p % (clusters - 1));
  cluster_of[0] = clusters - 1;  // one small cluster
  cpca::ClusterGrams grams;
  std::uniform_int_distribution<int> who(0, points - 1), where(0, clusters - 2);
  for (int round = 0; round < 6; ++round) {
    grams.sync(x, cluster_of, clusters);
    const auto members = cpca::cluster_members(cluster_of, clusters);
    for (int c = 0; c < clusters; ++c) {
      const Eigen::MatrixXd* g = grams.gram(std::uint32_t(c));
      if (members[std::size_t(c)].empty() ||
          Eigen::Index(members[std::size_t(c)].size()) >= dimension) {
        EXPECT_EQ(g, nullptr) << "cluster " << c << " is empty or on the covariance path";
        continue;
      }
      ASSERT_NE(g, nullptr) << "round " << round << " cluster " << c;
      EXPECT_EQ(grams.members(std::uint32_t(c)), members[std::size_t(c)]);
      const Eigen::MatrixXd expected = product(x, members[std::size_t(c)]);
      EXPECT_LT((*g - expected).cwiseAbs().maxCoeff(), 1e-12 * expected.cwiseAbs().maxCoeff());
    }
    for (int move = 0; move < 5 + 10 * round; ++move)
      cluster_of[std::size_t(who(rng))] = std::uint32_t(where(rng));
  }
  EXPECT_GT(grams.rows_computed(), 0u);
  // A budget of one small matrix keeps only the clusters that fit in it.
  cpca::ClusterGrams small(40 * 40 * sizeof(double));
  small.sync(x, cluster_of, clusters);
  int kept = 0;
  for (int c = 0; c < clusters; ++c) kept += small.gram(std::uint32_t(c)) != nullptr;
  EXPECT_LE(kept, 1);
}

TEST(ClusterGrams, WarmRefitWithThemEqualsTheRefitWithout) {
  const int points = 240, dimension = 96, clusters = 6;
  std::mt19937 rng(2);
  std::normal_distribution<float> value(0, 1);
  cpca::DataMatrix x(points, dimension);
  for (int p = 0; p < points; ++p)
    for (int j = 0; j < dimension; ++j)
      x(p, j) = value(rng) * std::pow(0.9f, float(j % 20)) + float(p % clusters);
  cpca::CompressedSet set;
  set.cluster_count = clusters;
  set.component_count = 4;
  set.cluster_of.resize(points);
  for (int p = 0; p < points; ++p) set.cluster_of[std::size_t(p)] = std::uint32_t(p % clusters);
  cpca::fit_cluster_pca(x, set, cpca::PcaSolver::kPowerIteration);
  const std::vector<float> previous = set.bases;
  for (int p = 0; p < 12; ++p)
    set.cluster_of[std::size_t(p * 17)] = std::uint32_t((p + 1) % clusters);
  cpca::ClusterGrams grams;
  grams.sync(x, set.cluster_of, clusters);
  std::vector<const Eigen::MatrixXd*> g(clusters);
  for (int c = 0; c < clusters; ++c) g[std::size_t(c)] = grams.gram(std::uint32_t(c));
  cpca::PowerIterationOptions o;
  o.tolerance = 1e-12;
  cpca::CompressedSet with = set, without = set;
  const std::vector<double> e1 = cpca::fit_cluster_pca_warm(x, with, previous, o, g);
  const std::vector<double> e0 = cpca::fit_cluster_pca_warm(x, without, previous, o);
  double t0 = 0, t1 = 0;
  for (std::size_t p = 0; p < e0.size(); ++p) t0 += e0[p], t1 += e1[p];
  EXPECT_NEAR(t1, t0, 1e-6 * t0);
  EXPECT_EQ(with.means, without.means);

  // Only some clusters, in place: those equal the full refit's, the others keep every number.
  std::vector<char> only(clusters, 0);
  only[1] = only[4] = 1;
  cpca::CompressedSet part = set;
  part.means.assign(with.means.size(), 7.f);
  part.bases.assign(with.bases.size(), 7.f);
  part.weights.assign(with.weights.size(), 7.f);
  const std::vector<double> e2 = cpca::fit_cluster_pca_warm(x, part, previous, o, g, only);
  const std::size_t d = dimension, n = 4;
  for (int c = 0; c < clusters; ++c) {
    const auto mean = [&](const cpca::CompressedSet& s) {
      return std::vector<float>(s.means.begin() + std::ptrdiff_t(c * d),
                                s.means.begin() + std::ptrdiff_t((c + 1) * d));
    };
    const auto basis = [&](const cpca::CompressedSet& s) {
      return std::vector<float>(s.bases.begin() + std::ptrdiff_t(c * n * d),
                                s.bases.begin() + std::ptrdiff_t((c + 1) * n * d));
    };
    if (only[std::size_t(c)]) {
      EXPECT_EQ(mean(part), mean(with)) << c;
      EXPECT_EQ(basis(part), basis(with)) << c;
    } else {
      EXPECT_EQ(mean(part), std::vector<float>(d, 7.f)) << c;
      EXPECT_EQ(basis(part), std::vector<float>(n * d, 7.f)) << c;
    }
  }
  for (int p = 0; p < points; ++p) {
    const int c = int(set.cluster_of[std::size_t(p)]);
    if (only[std::size_t(c)]) {
      EXPECT_EQ(e2[std::size_t(p)], e1[std::size_t(p)]) << p;
    } else {
      EXPECT_EQ(e2[std::size_t(p)], 0.0) << p;
      EXPECT_EQ(part.weights[std::size_t(p) * n], 7.f) << p;
    }
  }
  std::vector<char> wrong(clusters - 1, 1);
  EXPECT_THROW(cpca::fit_cluster_pca_warm(x, part, previous, o, g, wrong), std::invalid_argument);
}

}  // namespace
