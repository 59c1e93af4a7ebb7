// CPCA end to end on synthetic data with known answers: exact affine subspaces, error
// monotone in the component count, the two PCA solvers agree, iterative CPCA never loses to
// LBG + PCA, the overdraw-aware reassignment, and the triangle-span metric.
#include "cpca/compress.h"
#include "cpca/cluster_pca.h"

#include "cpca_test_support.h"

#include <gtest/gtest.h>
#include <Eigen/QR>

#include <algorithm>
#include <numeric>
#include <random>
#include <set>

namespace {

using cpca_test::grid;

// K affine subspaces of dimension `rank` in R^d, far apart: point = offset_k + U_k c.
cpca::DataMatrix affine_subspaces(int k, int per, int rank, int d, unsigned seed,
                                  std::vector<int>* truth = nullptr) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> n(0.0, 1.0);
  cpca::DataMatrix x(k * per, d);
  for (int c = 0; c < k; ++c) {
    Eigen::MatrixXd g(d, rank);
    for (int i = 0; i < d; ++i)
      for (int j = 0; j < rank; ++j) g(i, j) = n(rng);
    const Eigen::MatrixXd u = Eigen::HouseholderQR<Eigen::MatrixXd>(g).householderQ() *
                              Eigen::MatrixXd::Identity(d, rank);
    Eigen::VectorXd offset = Eigen::VectorXd::Zero(d);
    offset[c % d] = 50.0 * (1 + c / d);
    for (int p = 0; p < per; ++p) {
      Eigen::VectorXd coeff(rank);
      for (int j = 0; j < rank; ++j) coeff[j] = n(rng);
      x.row(c * per + p) = (offset + u * coeff).transpose().cast<float>();
      if (truth) truth->push_back(c);
    }
  }
  return x;
}

TEST(Compress, AffineSubspacesAreRecoveredExactly) {
  std::vector<int> truth;
  const cpca::DataMatrix x = affine_subspaces(5, 80, 3, 48, 1, &truth);
  for (cpca::ClusterMethod method : {cpca::ClusterMethod::kLbg, cpca::ClusterMethod::kIterative}) {
    for (cpca::PcaSolver solver : {cpca::PcaSolver::kPowerIteration, cpca::PcaSolver::kEigen}) {
      cpca::CompressOptions o;
      o.layout = {4, 3, 1};  // 48 numbers: diffuse RGB order 4 (glossy RGB order 2 too)
      o.clusters = 5;
      o.components = 3;
      o.method = method;
      o.solver = solver;
      cpca::CompressReport report;
      const cpca::CompressedSet set = cpca::compress(x, o, nullptr, &report);
      EXPECT_NO_THROW(cpca::validate(set));
      // Float data and storage: relative squared error at the level of float rounding
      // (~1e-14); 1e-10 leaves room and still fails for any real modelling error.
      EXPECT_LT(report.error.relative_error, 1e-10);
      const cpca::ErrorMetrics independent = cpca::error_metrics(x, set);
      EXPECT_LT(independent.relative_error, 1e-10);
      // Clusters are exactly the subspaces (up to relabelling).
      for (std::size_t p = 1; p < truth.size(); ++p)
        EXPECT_EQ(set.cluster_of[p] == set.cluster_of[p - 1], truth[p] == truth[p - 1]);
    }
  }
}

// Original CPCA's PCA stage on its own LBG clusters, without LBG: the same fit to the bit,
// and labels that do not fit the data or K are refused.
TEST(Compress, FitClusteringIsLbgPlusPcaWithoutLbg) {
  const cpca::DataMatrix x = affine_subspaces(5, 40, 2, 9, 21);
  cpca::CompressOptions o;
  o.clusters = 5;
  o.components = 2;
  o.layout = {3, 1, 1};
  const cpca::CompressedSet lbg = cpca::compress(x, o);
  std::vector<double> error;
  const cpca::CompressedSet fit = cpca::fit_clustering(x, o, lbg.cluster_of, &error);
  EXPECT_EQ(fit.cluster_of, lbg.cluster_of);
  EXPECT_EQ(fit.means, lbg.means);
  EXPECT_EQ(fit.bases, lbg.bases);
  EXPECT_EQ(fit.weights, lbg.weights);
  ASSERT_EQ(error.size(), std::size_t(x.rows()));
  const double total = std::accumulate(error.begin(), error.end(), 0.0);
  EXPECT_NEAR(total / double(x.rows()), cpca::error_metrics(x, lbg).average_squared_error,
              1e-6 * std::max(1.0, total));
  std::vector<std::uint32_t> short_labels(lbg.cluster_of.begin(), lbg.cluster_of.end() - 1);
  EXPECT_THROW(cpca::fit_clustering(x, o, short_labels), std::invalid_argument);
  std::vector<std::uint32_t> out_of_range = lbg.cluster_of;
  out_of_range[3] = 5;
  EXPECT_THROW(cpca::fit_clustering(x, o, out_of_range), std::invalid_argument);
}

TEST(Compress, ClustersEqualToVerticesGiveZeroError) {
  const cpca::DataMatrix x = affine_subspaces(3, 10, 5, 25, 2);
  cpca::CompressOptions o;
  o.clusters = 30;
  o.components = 2;
  cpca::CompressReport report;
  const cpca::CompressedSet set = cpca::compress(x, o, nullptr, &report);
  EXPECT_EQ(report.error.average_squared_error, 0.0);
  EXPECT_EQ(cpca::error_metrics(x, set).average_squared_error, 0.0);
}

TEST(Compress, ErrorFallsWeaklyAsComponentsGrow) {
  // Each cluster has rank 12, so components beyond 12 cannot help and before it each helps.
  const cpca::DataMatrix x = affine_subspaces(4, 60, 12, 36, 3);
  double previous = INFINITY;
  for (int n = 0; n <= 14; n += 2) {
    cpca::CompressOptions o;
    o.clusters = 6;  // more clusters than subspaces: the clustering is not trivial
    o.components = n;
    cpca::CompressReport report;
    cpca::compress(x, o, nullptr, &report);
    EXPECT_LE(report.error.average_squared_error, previous * (1 + 1e-6) + 1e-9) << n;
    previous = report.error.average_squared_error;
  }
}

TEST(Compress, PowerIterationAndEigenSolverGiveTheSameError) {
  std::mt19937 rng(4);
  std::normal_distribution<float> n(0.f, 1.f);
  cpca::DataMatrix x(900, 36);
  for (int i = 0; i < 900; ++i)
    for (int j = 0; j < 36; ++j) x(i, j) = n(rng) * std::pow(0.8f, float(j));
  cpca::CompressOptions o;
  o.clusters = 12;
  o.components = 4;
  cpca::CompressReport a, b;
  cpca::compress(x, o, nullptr, &a);
  o.solver = cpca::PcaSolver::kEigen;
  cpca::compress(x, o, nullptr, &b);
  EXPECT_NEAR(a.error.average_squared_error, b.error.average_squared_error,
              1e-4 * b.error.average_squared_error);
}

TEST(Compress, IterativeCpcaNeverLosesToLbgPlusPca) {
  std::mt19937 rng(6);
  std::normal_distribution<float> n(0.f, 1.f);
  cpca::DataMatrix x(1200, 25);
  for (int i = 0; i < 1200; ++i)
    for (int j = 0; j < 25; ++j)
      x(i, j) = n(rng) * (1.f + float(i % 7)) * std::pow(0.85f, float(j));
  cpca::CompressOptions o;
  o.clusters = 10;
  o.components = 3;
  cpca::CompressReport lbg, iterative;
  cpca::compress(x, o, nullptr, &lbg);
  o.method = cpca::ClusterMethod::kIterative;
  const cpca::CompressedSet set = cpca::compress(x, o, nullptr, &iterative);
  EXPECT_LT(iterative.error.average_squared_error, lbg.error.average_squared_error);
  for (std::size_t i = 1; i < iterative.cpca_error.size(); ++i)
    EXPECT_LT(iterative.cpca_error[i], iterative.cpca_error[i - 1]);
  EXPECT_NEAR(cpca::error_metrics(x, set).average_squared_error,
              iterative.error.average_squared_error, 1e-4 * iterative.error.average_squared_error);
}

// Options for 16-float points read as order-4 grey diffuse vectors (n = 16).
cpca::CompressOptions order4_options(int clusters, int components) {
  return {.layout = {4, 1, 1}, .clusters = clusters, .components = components};
}

TEST(SubspaceDistances, MatchReconstructionOfEveryPointInEveryCluster) {
  const cpca::DataMatrix x = affine_subspaces(3, 40, 4, 16, 7);
  const cpca::CompressedSet set = cpca::compress(x, order4_options(4, 2));
  const cpca::DataMatrix d = cpca::subspace_distances(x, x.rowwise().squaredNorm(), set);
  for (int p = 0; p < x.rows(); ++p)
    for (int k = 0; k < 4; ++k) {
      const Eigen::RowVectorXd c = (x.row(p) - set.mean(k)).cast<double>();
      const Eigen::MatrixXd b = set.basis(k).cast<double>();
      const double direct = (c - (c * b.transpose()) * b).squaredNorm();
      // The expanded form ||x||^2 - 2 x.m + ||m||^2 - ||Bx - Bm||^2 cancels in float: its
      // absolute error scales with ||x||^2 (here ~2500), not with the distance.
      const double scale = x.row(p).cast<double>().squaredNorm() + direct;
      ASSERT_NEAR(d(p, k), direct, 2e-6 * scale);
      ASSERT_NEAR(cpca::subspace_distance(x.row(p), set, k), direct, 1e-6 * (1 + direct));
    }
}

TEST(TriangleSpan, HandCount) {
  const std::vector<std::uint32_t> c = {0, 0, 1, 2, 1};
  const std::vector<cpca::TriangleIndices> t = {
      {0, 1, 0}, {0, 1, 2}, {0, 2, 3}, {2, 4, 2}, {3, 2, 0}};
  const cpca::TriangleSpan s = cpca::triangle_span(c, t);
  EXPECT_EQ(s.one, 2u);
  EXPECT_EQ(s.two, 1u);
  EXPECT_EQ(s.three, 2u);
}

TEST(OverdrawReduction, FewerStraddlingTrianglesWithinTheErrorBudget) {
  // Data smooth over a grid (a function of position), clustered without geometry: cluster
  // borders are ragged. The reassignment must cut straddling triangles and keep each move's
  // error increase within tolerance x Average SE.
  const cpca::Geometry g = grid(40);
  std::mt19937 rng(8);
  std::normal_distribution<float> n(0.f, 0.3f);
  cpca::DataMatrix x(1600, 16);
  for (int i = 0; i < 1600; ++i) {
    const Eigen::Vector3f& p = g.positions[std::size_t(i)];
    for (int j = 0; j < 16; ++j)
      x(i, j) = std::sin(3.f * p.x() * float(j + 1)) + std::cos(2.f * p.y() * float(j)) + n(rng);
  }
  cpca::CompressOptions o = order4_options(16, 3);
  cpca::CompressReport before, after;
  cpca::compress(x, o, &g, &before);
  o.overdraw_reduction = true;
  o.overdraw.tolerance = 0.5;
  const cpca::CompressedSet set = cpca::compress(x, o, &g, &after);
  EXPECT_GT(after.overdraw.moves, 0u);
  EXPECT_LT(after.span.multi(), before.span.multi());
  EXPECT_LE(after.overdraw.error_increase,
            double(after.overdraw.moves) * 0.5 * before.error.average_squared_error * (1 + 1e-9));
  // The refit can only lower the error of the moved clustering below the bookkept bound.
  EXPECT_LE(after.error.average_squared_error * 1600,
            before.error.average_squared_error * 1600 + after.overdraw.error_increase + 1e-6);
  EXPECT_EQ(std::set<std::uint32_t>(set.cluster_of.begin(), set.cluster_of.end()).size(), 16u);
}

TEST(Compress, RejectsBadParametersWithTheirNames) {
  const cpca::DataMatrix x = affine_subspaces(2, 10, 2, 9, 1);
  auto message = [&](cpca::CompressOptions o, const cpca::Geometry* g = nullptr) {
    try {
      cpca::compress(x, o, g);
    } catch (const std::invalid_argument& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  cpca::CompressOptions o;
  o.clusters = 21;
  EXPECT_NE(message(o).find("clusters"), std::string::npos);
  o.clusters = 2;
  o.components = 9;
  EXPECT_NE(message(o).find("PCs"), std::string::npos);
  o.components = 2;
  o.alpha = 0.05;
  EXPECT_NE(message(o).find("mesh"), std::string::npos);
  const cpca::Geometry wrong = grid(3);
  o.alpha = 0;
  EXPECT_NE(message(o, &wrong).find("vertices"), std::string::npos);
  cpca::DataMatrix bad = x;
  bad(3, 3) = NAN;
  o = {};
  o.clusters = 2;
  o.components = 2;
  EXPECT_THROW(cpca::compress(bad, o), std::invalid_argument);
}

TEST(Compress, AmbiguousDimensionIsRefusedNotGuessed) {
  // 16 numbers are diffuse order 4 or glossy order 2, 81 diffuse order 9 or glossy order 3:
  // without a layout the data cannot say which, and a guess renders nonsense.
  for (int d : {16, 81}) {
    const cpca::DataMatrix x = affine_subspaces(2, 10, 2, d, 1);
    cpca::CompressOptions o;
    o.clusters = 2;
    o.components = 1;
    try {
      cpca::compress(x, o);
      ADD_FAILURE() << d << " numbers were accepted without a layout";
    } catch (const std::invalid_argument& e) {
      EXPECT_NE(std::string(e.what()).find("diffuse order"), std::string::npos) << e.what();
      EXPECT_NE(std::string(e.what()).find("glossy order"), std::string::npos) << e.what();
    }
    o.layout = {d == 16 ? 2 : 3, 1, d == 16 ? 4 : 9};
    const cpca::CompressedSet set = cpca::compress(x, o);
    EXPECT_TRUE(set.glossy());
  }
  // An unambiguous size is still inferred: 9 numbers are only diffuse order 3.
  cpca::CompressOptions o;
  o.clusters = 2;
  o.components = 1;
  const cpca::CompressedSet set = cpca::compress(affine_subspaces(2, 10, 2, 9, 1), o);
  EXPECT_EQ(set.order, 3);
  EXPECT_FALSE(set.glossy());
}

}  // namespace

namespace {

TEST(SubspaceDistances, CandidateRestrictionAgreesWithTheFullMatrix) {
  const cpca::DataMatrix x = affine_subspaces(6, 30, 3, 16, 9);
  const cpca::CompressedSet set = cpca::compress(x, order4_options(6, 2));
  const Eigen::VectorXf norms = x.rowwise().squaredNorm();
  const cpca::DataMatrix full = cpca::subspace_distances(x, norms, set);
  const cpca::DataMatrix some = cpca::subspace_distances(x, norms, set, 2);
  const cpca::DataMatrix means = Eigen::Map<const cpca::DataMatrix>(set.means.data(), 6, 16);
  for (int p = 0; p < x.rows(); ++p) {
    int finite = 0;
    for (int k = 0; k < 6; ++k) {
      if (!std::isfinite(some(p, k))) continue;
      ++finite;
      EXPECT_NEAR(some(p, k), full(p, k), 2e-6 * (norms[p] + full(p, k)));
    }
    EXPECT_GE(finite, 2);
    EXPECT_LE(finite, 3);
    EXPECT_TRUE(std::isfinite(some(p, int(set.cluster_of[std::size_t(p)]))));
    // The two nearest means are among the candidates.
    Eigen::Index nearest = 0;
    (means.rowwise() - x.row(p)).rowwise().squaredNorm().minCoeff(&nearest);
    EXPECT_TRUE(std::isfinite(some(p, int(nearest))));
  }
}

TEST(SubspaceDistances, ClusterClosureHoldsTheOwnClustersNearestMeans) {
  const int k = 6;
  const cpca::DataMatrix x = affine_subspaces(k, 30, 3, 16, 9);
  const cpca::CompressedSet set = cpca::compress(x, order4_options(k, 2));
  const cpca::DataMatrix full = cpca::subspace_distances(x, x.rowwise().squaredNorm(), set);
  const cpca::DataMatrix near = cpca::subspace_distances_near_clusters(x, set, 3);
  const cpca::DataMatrix means = Eigen::Map<const cpca::DataMatrix>(set.means.data(), k, 16);
  for (int p = 0; p < x.rows(); ++p) {
    const int own = int(set.cluster_of[std::size_t(p)]);
    // The closure by brute force: the 3 means nearest the own cluster's mean (itself first).
    std::vector<std::pair<float, int>> by_mean;
    for (int c = 0; c < k; ++c)
      by_mean.push_back({(means.row(c) - means.row(own)).squaredNorm(), c});
    std::sort(by_mean.begin(), by_mean.end());
    std::set<int> closure;
    for (int i = 0; i < 3; ++i) closure.insert(by_mean[std::size_t(i)].second);
    for (int c = 0; c < k; ++c) {
      EXPECT_EQ(std::isfinite(near(p, c)), closure.count(c) == 1) << p << " " << c;
      if (std::isfinite(near(p, c))) {
        EXPECT_NEAR(near(p, c), full(p, c), 2e-6 * (x.row(p).squaredNorm() + full(p, c)));
      }
    }
    EXPECT_TRUE(closure.count(own));
  }
  // More candidates than clusters: every column.
  const cpca::DataMatrix all = cpca::subspace_distances_near_clusters(x, set, 100);
  EXPECT_TRUE(all.allFinite());
}

}  // namespace
