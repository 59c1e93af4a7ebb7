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

}  // namespace
