// LBG clustering, distances and the k-d tree against brute force; null-cluster avoidance;
// geometry coherence against a brute-force evaluation of thesis eq. 9-10.
#include "cpca/lbg.h"
#include "cpca/assignment.h"
#include "cpca/kd_tree.h"

#include "cpca_test_support.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <set>

namespace {

using cpca_test::grid;

cpca::DataMatrix random_data(int rows, int cols, unsigned seed, float scale = 1.f) {
  std::mt19937 rng(seed);
  std::normal_distribution<float> n(0.f, scale);
  cpca::DataMatrix x(rows, cols);
  for (int i = 0; i < rows; ++i)
    for (int j = 0; j < cols; ++j) x(i, j) = n(rng);
  return x;
}

// Points around `centres` well-separated blobs.
cpca::DataMatrix blobs(int per_blob, int blobs, int cols, unsigned seed) {
  cpca::DataMatrix x = random_data(per_blob * blobs, cols, seed, 0.05f);
  for (int b = 0; b < blobs; ++b)
    for (int i = 0; i < per_blob; ++i) x(b * per_blob + i, b % cols) += 10.f * float(1 + b / cols);
  return x;
}

TEST(KdTree, NearestMatchesBruteForceWithRadiusAndExclusion) {
  std::mt19937 rng(3);
  std::uniform_real_distribution<float> u(-1.f, 1.f);
  std::vector<Eigen::Vector3f> pts;
  std::vector<std::uint32_t> ids;
  for (std::uint32_t i = 0; i < 500; ++i) {
    pts.emplace_back(u(rng), u(rng), u(rng));
    ids.push_back(1000 + i);
  }
  pts.push_back(pts[7]);  // a duplicate point
  ids.push_back(2000);
  const cpca::KdTree tree(pts, ids);
  for (int q = 0; q < 300; ++q) {
    const Eigen::Vector3f p(u(rng), u(rng), u(rng));
    const float radius = q % 3 == 0 ? INFINITY : 0.05f + 0.3f * float(q % 5) / 5.f;
    const std::uint32_t exclude = q % 2 ? ids[std::size_t(q)] : cpca::KdTree::kNone;
    float best = radius;
    std::uint32_t best_id = cpca::KdTree::kNone;
    for (std::size_t i = 0; i < pts.size(); ++i) {
      const float d = (pts[i] - p).norm();
      if (ids[i] != exclude && d < best) best = d, best_id = ids[i];
    }
    const cpca::KdTree::Hit hit = tree.nearest(p, radius, exclude);
    if (best_id == cpca::KdTree::kNone) {
      EXPECT_EQ(hit.id, cpca::KdTree::kNone);
    } else {
      EXPECT_NEAR(hit.distance, best, 1e-6f);
    }
  }
}

TEST(Distances, MatrixProductFormEqualsDirectDifference) {
  const cpca::DataMatrix x = random_data(700, 37, 1), c = random_data(9, 37, 2);
  const Eigen::VectorXf norms = x.rowwise().squaredNorm();
  const cpca::DataMatrix d = cpca::squared_distances(x, norms, c);
  for (int i = 0; i < x.rows(); ++i)
    for (int j = 0; j < c.rows(); ++j) {
      const double direct = (x.row(i) - c.row(j)).cast<double>().squaredNorm();
      ASSERT_NEAR(d(i, j), direct, 1e-4 * (1 + direct));
    }
}

TEST(Lbg, NeverReturnsAnEmptyCluster) {
  for (unsigned seed = 1; seed <= 6; ++seed) {
    // Few points per cluster, and duplicates, to provoke null clusters.
    cpca::DataMatrix x = random_data(120, 10, seed);
    x.bottomRows(40) = x.topRows(1).replicate(40, 1);
    for (int k : {1, 7, 40, 81, 119}) {
      cpca::LbgOptions o;
      o.clusters = k;
      o.seed = seed;
      const cpca::LbgResult r = cpca::lbg(x, o);
      std::vector<int> count(std::size_t(k), 0);
      for (std::uint32_t c : r.cluster_of) {
        ASSERT_LT(c, std::uint32_t(k));
        ++count[c];
      }
      for (int j = 0; j < k; ++j)
        EXPECT_GT(count[std::size_t(j)], 0) << "k " << k << " cluster " << j;
    }
  }
}

TEST(Lbg, ClustersEqualToPointsGiveZeroEnergy) {
  const cpca::DataMatrix x = random_data(50, 6, 9);
  cpca::LbgOptions o;
  o.clusters = 50;
  const cpca::LbgResult r = cpca::lbg(x, o);
  EXPECT_EQ(r.energy.back(), 0.0);
  EXPECT_EQ(std::set<std::uint32_t>(r.cluster_of.begin(), r.cluster_of.end()).size(), 50u);
}

TEST(Lbg, EnergyNeverRisesAndBlobsAreFound) {
  const cpca::DataMatrix x = blobs(60, 8, 12, 4);
  cpca::LbgOptions o;
  o.clusters = 8;
  o.threshold = 0;
  o.max_iterations = 30;
  const cpca::LbgResult r = cpca::lbg(x, o);
  for (std::size_t i = 1; i < r.energy.size(); ++i)
    EXPECT_LE(r.energy[i], r.energy[i - 1] * (1 + 1e-9));
  // Each blob in one cluster, each cluster one blob.
  for (int b = 0; b < 8; ++b)
    for (int i = 1; i < 60; ++i)
      EXPECT_EQ(r.cluster_of[std::size_t(b * 60 + i)], r.cluster_of[std::size_t(b * 60)]);
  EXPECT_EQ(std::set<std::uint32_t>(r.cluster_of.begin(), r.cluster_of.end()).size(), 8u);
  // Energy eq. 4 recomputed by hand.
  const cpca::DataMatrix means = cpca::cluster_means(x, r.cluster_of, 8);
  double e = 0;
  for (int p = 0; p < x.rows(); ++p)
    e += (x.row(p) - means.row(r.cluster_of[std::size_t(p)])).cast<double>().squaredNorm();
  EXPECT_NEAR(r.energy.back(), e, 1e-9 * e);
}

TEST(Lbg, StopsOnTheConvergedRatio) {
  const cpca::DataMatrix x = random_data(400, 8, 5);
  cpca::LbgOptions o;
  o.clusters = 12;
  o.threshold = 1e-2;
  const cpca::LbgResult r = cpca::lbg(x, o);
  ASSERT_GE(r.energy.size(), 2u);
  const std::size_t n = r.energy.size();
  EXPECT_LT((r.energy[n - 2] - r.energy[n - 1]) / r.energy[n - 2], 1e-2);
  for (std::size_t i = 1; i + 1 < n; ++i)
    EXPECT_GE((r.energy[i - 1] - r.energy[i]) / r.energy[i - 1], 1e-2);
}

TEST(Lbg, RejectsImpossibleClusterCounts) {
  const cpca::DataMatrix x = random_data(5, 3, 1);
  cpca::LbgOptions o;
  o.clusters = 6;
  EXPECT_THROW(cpca::lbg(x, o), std::invalid_argument);
  o.clusters = 0;
  EXPECT_THROW(cpca::lbg(x, o), std::invalid_argument);
}

TEST(GeometryCoherence, AlphaZeroReproducesPlainLbgExactly) {
  const cpca::Geometry g = grid(20);
  const cpca::DataMatrix x = random_data(400, 16, 11);
  const cpca::GeometryCoherence off(g, 400, 0.0);
  for (unsigned seed : {1u, 2u, 3u}) {
    cpca::LbgOptions o;
    o.clusters = 17;
    o.seed = seed;
    o.threshold = 0;
    o.max_iterations = 15;
    const cpca::LbgResult plain = cpca::lbg(x, o), coherent = cpca::lbg(x, o, &off);
    EXPECT_EQ(plain.cluster_of, coherent.cluster_of);
    EXPECT_EQ(plain.energy, coherent.energy);
  }
}

TEST(GeometryCoherence, AssignmentEqualsBruteForceEquation9) {
  const cpca::Geometry g = grid(16);
  const int v = 256, k = 9;
  const cpca::DataMatrix x = random_data(v, 5, 12), c = random_data(k, 5, 13);
  const cpca::DataMatrix d2 = cpca::squared_distances(x, x.rowwise().squaredNorm(), c);
  std::vector<std::uint32_t> previous(static_cast<std::size_t>(v));
  std::mt19937 rng(5);
  for (auto& p : previous) p = rng() % std::uint32_t(k);
  const double alpha = 0.7, scale = 1.3;
  const cpca::GeometryCoherence coherence(g, v, alpha);
  const std::vector<std::uint32_t> got = coherence.assign(d2, previous, scale);
  const float diag = std::sqrt(2.f);
  for (int i = 0; i < v; ++i) {
    double best = INFINITY;
    int best_j = -1;
    for (int j = 0; j < k; ++j) {
      double geo = INFINITY;
      int members = 0;
      for (int q = 0; q < v; ++q)
        if (previous[std::size_t(q)] == std::uint32_t(j)) {
          ++members;
          if (q != i)
            geo = std::min(
                geo,
                double((g.positions[std::size_t(q)] - g.positions[std::size_t(i)]).norm() / diag));
        }
      if (members == 0 || (members == 1 && previous[std::size_t(i)] == std::uint32_t(j))) geo = 0;
      const double total = std::sqrt(double(d2(i, j))) / scale + alpha * geo;
      if (total < best) best = total, best_j = j;
    }
    EXPECT_EQ(got[std::size_t(i)], std::uint32_t(best_j)) << "vertex " << i;
  }
}

TEST(GeometryCoherence, LargeAlphaKeepsClustersSpatiallyCompact) {
  // A smooth field over the grid plus strong noise: plain LBG leaves ragged, interleaved
  // clusters; a large alpha pulls each vertex toward clusters with members nearby.
  const cpca::Geometry g = grid(30);
  cpca::DataMatrix x = random_data(900, 4, 21, 0.5f);
  for (int i = 0; i < 900; ++i) {  // a smooth field over the grid plus noise
    const Eigen::Vector3f& p = g.positions[std::size_t(i)];
    x(i, 0) += 2.f * p.x();
    x(i, 1) += 2.f * p.y();
  }
  cpca::LbgOptions o;
  o.clusters = 10;
  o.threshold = 0;
  o.max_iterations = 25;
  const cpca::GeometryCoherence strong(g, 900, 10.0);
  auto straddling = [&](const std::vector<std::uint32_t>& c) {
    int n = 0;
    for (const auto& t : g.triangles) n += !(c[t[0]] == c[t[1]] && c[t[1]] == c[t[2]]);
    return n;
  };
  const int plain = straddling(cpca::lbg(x, o).cluster_of);
  const int coherent = straddling(cpca::lbg(x, o, &strong).cluster_of);
  EXPECT_LT(coherent, 0.92 * plain) << "plain " << plain << " coherent " << coherent;
}

TEST(SplitEmptyClusters, FillsEveryClusterAndLowersEnergy) {
  const cpca::DataMatrix x = blobs(30, 4, 6, 8);
  std::vector<std::uint32_t> all_zero(120, 0);
  const double before = cpca::clustering_energy(x, all_zero, cpca::cluster_means(x, all_zero, 1));
  EXPECT_EQ(cpca::split_empty_clusters(x, all_zero, 4), 3);
  std::set<std::uint32_t> used(all_zero.begin(), all_zero.end());
  EXPECT_EQ(used.size(), 4u);
  EXPECT_LT(cpca::clustering_energy(x, all_zero, cpca::cluster_means(x, all_zero, 4)), before);
}

TEST(SplitEmptyClusters, ALargeClusterSplitsBetweenItsTwoBlobs) {
  // 6000 rows in one cluster, more than the split's sample: the direction comes from the
  // sample, and every row, sampled or not, must land on its blob's side.
  std::mt19937 rng(5);
  std::normal_distribution<float> noise(0.f, 0.3f);
  cpca::DataMatrix x(6000, 8);
  for (Eigen::Index i = 0; i < x.rows(); ++i)
    for (Eigen::Index d = 0; d < x.cols(); ++d)
      x(i, d) = noise(rng) + (i % 2 == 0 ? 4.f : -4.f) * float(d == 3);
  std::vector<std::uint32_t> cluster_of(6000, 0);
  EXPECT_EQ(cpca::split_empty_clusters(x, cluster_of, 2), 1);
  for (Eigen::Index i = 2; i < x.rows(); ++i)
    ASSERT_EQ(cluster_of[std::size_t(i)], cluster_of[std::size_t(i % 2)]) << "row " << i;
  EXPECT_NE(cluster_of[0], cluster_of[1]);
}

}  // namespace
