// Patch-first CPCA: on meshes whose patches are known (disjoint grids, each made of stripes
// of constant transfer) it must find the patches, draw every triangle once and recover the
// stripes exactly; on a connected grid its designed passes must draw exactly the triangles
// a brute-force count over the patches gives.
#include "cpca/patch_first.h"

#include "cpca/compress.h"
#include "cpca_test_support.h"

#include <gtest/gtest.h>

#include <map>
#include <random>
#include <set>

namespace {

// `grids` copies of an n x n grid, 2 units apart in x, so no triangle joins two of them.
cpca::Geometry disjoint_grids(int grids, int n) {
  cpca::Geometry all;
  for (int g = 0; g < grids; ++g) {
    const cpca::Geometry one = cpca_test::grid(n);
    const auto base = std::uint32_t(all.positions.size());
    for (Eigen::Vector3f p : one.positions)
      all.positions.push_back(p + Eigen::Vector3f(2.f * g, 0, 0));
    for (cpca::TriangleIndices t : one.triangles)
      all.triangles.push_back({t[0] + base, t[1] + base, t[2] + base});
  }
  return all;
}

TEST(PatchFirst, ClusterCountsFillPassesInOrder) {
  EXPECT_EQ(cpca::patch_cluster_counts(10, 3), (std::vector<int>{3, 3, 3, 1}));
  EXPECT_EQ(cpca::patch_cluster_counts(6, 3), (std::vector<int>{3, 3}));
  EXPECT_EQ(cpca::patch_cluster_counts(2, 16), (std::vector<int>{2}));
  EXPECT_THROW(cpca::patch_cluster_counts(4, 0), std::invalid_argument);
}

TEST(PatchFirst, KnownPatchesGiveOverdrawOneAndExactClusters) {
  const int grids = 4, n = 10, per_pass = 3;
  const cpca::Geometry g = disjoint_grids(grids, n);
  // Grid g, column band b (x in thirds) holds one constant vector: the stripes are the
  // clusters, the grids the patches.
  std::mt19937 rng(7);
  std::uniform_real_distribution<float> u(-1.f, 1.f);
  std::vector<Eigen::Matrix<float, 1, 9>> value(std::size_t(grids * per_pass));
  for (auto& v : value)
    for (int i = 0; i < 9; ++i) v[i] = u(rng);
  cpca::DataMatrix x(Eigen::Index(g.positions.size()), 9);
  std::vector<int> stripe(g.positions.size());
  for (std::size_t p = 0; p < g.positions.size(); ++p) {
    const int grid = int(p) / (n * n), column = int(p) % n;
    stripe[p] = grid * per_pass + std::min(column * per_pass / n, per_pass - 1);
    x.row(Eigen::Index(p)) = value[std::size_t(stripe[p])];
  }
  cpca::CompressOptions o;
  o.layout = {3, 1, 1};
  o.clusters = grids * per_pass;
  o.components = 0;
  o.clusters_per_pass = per_pass;
  o.method = cpca::ClusterMethod::kPatchFirst;
  cpca::CompressReport report;
  const cpca::CompressedSet set = cpca::compress(x, o, &g, &report);
  ASSERT_NO_THROW(cpca::validate(set));
  EXPECT_EQ(set.method, cpca::ClusterMethod::kPatchFirst);
  const cpca::OverdrawStats stats =
      cpca::overdraw(set.cluster_of, g.triangles, cpca::designed_passes(set, per_pass));
  EXPECT_EQ(stats.triangles_drawn, g.triangles.size());
  EXPECT_EQ(stats.average_overdraw, 1.0);
  // One cluster per stripe and one stripe per cluster.
  std::map<std::uint32_t, std::set<int>> stripes_of;
  std::map<int, std::set<std::uint32_t>> clusters_of;
  for (std::size_t p = 0; p < stripe.size(); ++p) {
    stripes_of[set.cluster_of[p]].insert(stripe[p]);
    clusters_of[stripe[p]].insert(set.cluster_of[p]);
  }
  EXPECT_EQ(stripes_of.size(), std::size_t(grids * per_pass));
  for (const auto& [c, s] : stripes_of) EXPECT_EQ(s.size(), 1u) << "cluster " << c;
  for (const auto& [s, c] : clusters_of) EXPECT_EQ(c.size(), 1u) << "stripe " << s;
  EXPECT_LT(report.error.average_squared_error, 1e-12);
  EXPECT_LT(cpca::error_metrics(x, set).average_squared_error, 1e-12);
}

TEST(PatchFirst, DesignedPassesDrawWhatThePatchesPredict) {
  const int n = 24, per_pass = 3, clusters = 10;
  const cpca::Geometry g = cpca_test::grid(n);
  cpca::DataMatrix x(Eigen::Index(n * n), 9);
  for (int p = 0; p < n * n; ++p)
    for (int i = 0; i < 9; ++i)
      x(p, i) = std::sin(float(i + 1) * g.positions[std::size_t(p)].x()) +
                std::cos(float(9 - i) * g.positions[std::size_t(p)].y());
  const std::vector<int> counts = cpca::patch_cluster_counts(clusters, per_pass);
  const std::vector<std::uint32_t> patch = cpca::partition_patches(x, g, counts, 1);
  cpca::CompressOptions o;
  o.layout = {3, 1, 1};
  o.clusters = clusters;
  o.components = 2;
  o.clusters_per_pass = per_pass;
  o.method = cpca::ClusterMethod::kPatchFirst;
  const cpca::CompressedSet set = cpca::compress(x, o, &g);
  ASSERT_NO_THROW(cpca::validate(set));
  std::vector<int> patch_size(counts.size(), 0);
  for (std::size_t p = 0; p < patch.size(); ++p) {
    EXPECT_EQ(set.cluster_of[p] / per_pass, patch[p]) << "vertex " << p;
    ++patch_size[patch[p]];
  }
  for (std::size_t q = 0; q < counts.size(); ++q) EXPECT_GE(patch_size[q], counts[q]);
  // Brute force: a triangle is drawn once per distinct patch among its corners.
  std::uint64_t drawn = 0;
  for (const cpca::TriangleIndices& t : g.triangles)
    drawn += std::set<std::uint32_t>{patch[t[0]], patch[t[1]], patch[t[2]]}.size();
  const cpca::OverdrawStats stats =
      cpca::overdraw(set.cluster_of, g.triangles, cpca::designed_passes(set, per_pass));
  EXPECT_EQ(stats.triangles_drawn, drawn);
  EXPECT_GT(drawn, g.triangles.size());  // a connected grid cut in 4 has borders
  // Every cluster of every pass holds vertices.
  EXPECT_EQ(std::set<std::uint32_t>(set.cluster_of.begin(), set.cluster_of.end()).size(),
            std::size_t(clusters));
}

TEST(PatchFirst, NeedsTheMesh) {
  cpca::DataMatrix x = cpca::DataMatrix::Random(20, 9);
  cpca::CompressOptions o;
  o.layout = {3, 1, 1};
  o.clusters = 4;
  o.components = 1;
  o.method = cpca::ClusterMethod::kPatchFirst;
  EXPECT_THROW(cpca::compress(x, o), std::invalid_argument);
}

// Each cluster of the clustering weighs the same in all: a vertex of a cluster of n weighs
// 1 / n of a unit, so small clusters' vertices weigh more.
TEST(PatchFirst, ClusterDensityWeightsGiveEveryClusterTheSameWeight) {
  const std::vector<std::uint32_t> cluster_of = {0, 0, 0, 0, 1, 2, 2, 1, 0, 2};
  const std::vector<std::uint32_t> w = cpca::cluster_density_weights(cluster_of, 3);
  ASSERT_EQ(w.size(), cluster_of.size());
  std::vector<double> total(3, 0);
  for (std::size_t v = 0; v < w.size(); ++v) total[cluster_of[v]] += w[v];
  for (double t : total) EXPECT_NEAR(t, total[0], 2.0);  // integer rounding, one per vertex
  EXPECT_GT(w[4], w[0]);                 // cluster 1 has 2 vertices, cluster 0 has 5
  EXPECT_GT(double(total[0]) * 3, 9e8);  // the sum uses most of METIS's 32 bits, and fits
  EXPECT_LT(double(total[0]) * 3, 2.1e9);
  EXPECT_THROW(cpca::cluster_density_weights(cluster_of, 2), std::invalid_argument);
}

// Patches balance the vertices' weight, not their count: with the left half of a grid
// weighing 3 times the right, every patch holds about the same weight, so those on the left
// hold fewer vertices; unweighted, every patch holds about the same number of vertices.
TEST(PatchFirst, PatchesBalanceVertexWeights) {
  const int n = 32;
  const cpca::Geometry g = cpca_test::grid(n);
  cpca::DataMatrix x(Eigen::Index(n * n), 3);
  for (int p = 0; p < n * n; ++p)
    x.row(p) = g.positions[std::size_t(p)].transpose();  // similarity weights near uniform
  std::vector<std::uint32_t> weight(std::size_t(n * n));
  for (int p = 0; p < n * n; ++p)
    weight[std::size_t(p)] = g.positions[std::size_t(p)].x() < 0.5f ? 3 : 1;
  const std::vector<int> counts(8, 3);
  struct Spread {
    double weight, size;  // largest over smallest patch
  };
  auto spread = [&](const std::vector<std::uint32_t>& of) {
    std::vector<double> w(8, 0), size(8, 0);
    for (int p = 0; p < n * n; ++p) {
      w[of[std::size_t(p)]] += weight[std::size_t(p)];
      size[of[std::size_t(p)]] += 1;
    }
    return Spread{
        *std::max_element(w.begin(), w.end()) / *std::min_element(w.begin(), w.end()),
        *std::max_element(size.begin(), size.end()) / *std::min_element(size.begin(), size.end())};
  };
  const Spread weighted = spread(cpca::partition_patches(x, g, counts, 1, weight));
  EXPECT_LT(weighted.weight, 1.1);
  EXPECT_GT(weighted.size, 2.0);  // 3 ideally: a left patch has a third of a right one's
  const Spread plain = spread(cpca::partition_patches(x, g, counts, 1));
  EXPECT_LT(plain.size, 1.1);
  EXPECT_GT(plain.weight, 2.0);
  EXPECT_THROW(cpca::partition_patches(x, g, counts, 1, std::vector<std::uint32_t>(5, 1)),
               std::invalid_argument);
}

// Equal compact passes of a 20 x 20 grid: one pass draws every triangle once; two equal halves
// cost at least a straight cut (19 cells, 38 triangles drawn twice, 1 + 38 / 722), and METIS
// finds one within a few cells of it; more passes cost more.
TEST(PatchFirst, EqualPatchesOverdrawIsNearTheShortestCut) {
  const cpca::Geometry g = cpca_test::grid(20);
  EXPECT_EQ(cpca::equal_patches_overdraw(g, 1, 1), 1.0);
  const double straight = 1.0 + 38.0 / 722.0;
  const double two = cpca::equal_patches_overdraw(g, 2, 1);
  EXPECT_GE(two, straight - 1e-12);
  EXPECT_LT(two, 1.0 + 1.3 * 38.0 / 722.0);
  EXPECT_GT(cpca::equal_patches_overdraw(g, 8, 1), two);
  EXPECT_THROW(cpca::equal_patches_overdraw(g, 0, 1), std::invalid_argument);
  EXPECT_THROW(cpca::equal_patches_overdraw(g, 401, 1), std::invalid_argument);
}

}  // namespace
