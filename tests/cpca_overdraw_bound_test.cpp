// The grouping overdraw bound: never above what any strategy reaches on small meshes, never
// above the true optimum found by enumerating every grouping of a few clusters, and equal to
// it on a chain of clusters whose heavy pairs can all share a pass.
#include "cpca/overdraw_bound.h"

#include "cpca/supercluster.h"
#include "cpca/supercluster_strategy.h"
#include "cpca_test_support.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <functional>
#include <limits>
#include <random>
#include <set>

namespace {

// Triangles drawn by a grouping, counted per triangle (independent of the incidence).
std::uint64_t draws(const std::vector<std::uint32_t>& cluster_of,
                    const std::vector<cpca::TriangleIndices>& triangles,
                    const std::vector<std::uint32_t>& pass_of) {
  std::uint64_t n = 0;
  for (const cpca::TriangleIndices& t : triangles)
    n += std::set<std::uint32_t>{pass_of[cluster_of[t[0]]], pass_of[cluster_of[t[1]]],
                                 pass_of[cluster_of[t[2]]]}
             .size();
  return n;
}

// The least draws over every assignment of k clusters to passes of at most per_pass clusters
// (restricted growth strings: pass p opens only after pass p - 1).
std::uint64_t brute_force_minimum(const std::vector<std::uint32_t>& cluster_of,
                                  const std::vector<cpca::TriangleIndices>& triangles, int k,
                                  int per_pass) {
  std::vector<std::uint32_t> pass_of(std::size_t(k), 0);
  std::vector<int> size(std::size_t(k), 0);
  std::uint64_t best = std::numeric_limits<std::uint64_t>::max();
  std::function<void(int, std::uint32_t)> place = [&](int c, std::uint32_t passes) {
    if (c == k) {
      best = std::min(best, draws(cluster_of, triangles, pass_of));
      return;
    }
    for (std::uint32_t p = 0; p <= passes && p < std::uint32_t(k); ++p) {
      if (size[p] == per_pass) continue;
      pass_of[std::size_t(c)] = p;
      ++size[p];
      place(c + 1, std::max(passes, p + 1));
      --size[p];
    }
  };
  place(0, 0);
  return best;
}

// Random clusters grown from seeds over the grid (spatially patchy, as real clusterings).
std::vector<std::uint32_t> grown_clusters(const cpca::Geometry& g, int n, int k, unsigned seed) {
  std::mt19937 rng(seed);
  std::vector<std::uint32_t> cluster_of(g.positions.size(), ~0u);
  std::vector<std::uint32_t> frontier;
  std::uniform_int_distribution<std::uint32_t> pick(0, std::uint32_t(g.positions.size() - 1));
  for (int c = 0; c < k; ++c) {
    std::uint32_t v = pick(rng);
    while (cluster_of[v] != ~0u) v = pick(rng);
    cluster_of[v] = std::uint32_t(c);
    frontier.push_back(v);
  }
  while (!frontier.empty()) {
    std::uniform_int_distribution<std::size_t> at(0, frontier.size() - 1);
    const std::size_t i = at(rng);
    const std::uint32_t v = frontier[i];
    const int x = int(v) % n, y = int(v) / n;
    bool grew = false;
    for (const auto& [dx, dy] :
         {std::pair{1, 0}, std::pair{-1, 0}, std::pair{0, 1}, std::pair{0, -1}}) {
      const int nx = x + dx, ny = y + dy;
      if (nx < 0 || ny < 0 || nx >= n || ny >= n) continue;
      const std::uint32_t w = std::uint32_t(ny * n + nx);
      if (cluster_of[w] != ~0u) continue;
      cluster_of[w] = cluster_of[v];
      frontier.push_back(w);
      grew = true;
      break;
    }
    if (!grew) frontier.erase(frontier.begin() + std::ptrdiff_t(i));
  }
  return cluster_of;
}

TEST(GroupingBound, EqualsTheBruteForceOnAChain) {
  // Four vertical bands of three columns on a 12 x 12 grid, each border 22 triangles. With 2
  // per pass the best grouping is {0, 1}, {2, 3}: only the 1|2 border is drawn twice, 22
  // extra draws, and the bound (clusters 1 and 2 each keep one border of two) says the same.
  const int n = 12;
  const cpca::Geometry g = cpca_test::grid(n);
  std::vector<std::uint32_t> cluster_of(g.positions.size());
  for (std::size_t v = 0; v < cluster_of.size(); ++v)
    cluster_of[v] = std::uint32_t(std::min<std::size_t>(3, (v % std::size_t(n)) / 3));
  const cpca::SuperClusterInput input{cluster_of, g.triangles, 4, 2};
  const cpca::GroupingBound b = cpca::grouping_overdraw_bound(input);
  const std::uint64_t best = brute_force_minimum(cluster_of, g.triangles, 4, 2);
  EXPECT_GT(best, g.triangles.size());
  EXPECT_EQ(b.triangles_drawn, best);
  EXPECT_DOUBLE_EQ(b.average_overdraw, double(best) / double(g.triangles.size()));
}

TEST(GroupingBound, NeverAboveTheBruteForceMinimum) {
  const int n = 9;
  const cpca::Geometry g = cpca_test::grid(n);
  for (unsigned seed = 1; seed <= 12; ++seed)
    for (int per_pass : {1, 2, 3}) {
      const int k = 6 + int(seed % 2);
      const std::vector<std::uint32_t> cluster_of = grown_clusters(g, n, k, seed);
      const cpca::SuperClusterInput input{cluster_of, g.triangles, k, per_pass};
      const std::uint64_t best = brute_force_minimum(cluster_of, g.triangles, k, per_pass);
      const cpca::GroupingBound b = cpca::grouping_overdraw_bound(input);
      EXPECT_LE(b.triangles_drawn, best) << "seed " << seed << ", per pass " << per_pass;
      EXPECT_GE(b.triangles_drawn, g.triangles.size());
    }
}

TEST(GroupingBound, NeverAboveAnyStrategy) {
  const int n = 24;
  const cpca::Geometry g = cpca_test::grid(n);
  for (unsigned seed = 1; seed <= 4; ++seed)
    for (int per_pass : {2, 3, 5}) {
      const int k = 20 + int(seed);
      const std::vector<std::uint32_t> cluster_of = grown_clusters(g, n, k, seed);
      const cpca::SuperClusterInput input{cluster_of, g.triangles, k, per_pass};
      const cpca::GroupingBound b = cpca::grouping_overdraw_bound(input);
      for (const cpca::NamedStrategy& s : cpca::supercluster_strategies()) {
        const cpca::OverdrawStats od =
            cpca::overdraw(cluster_of, g.triangles, cpca::group_clusters(s.name, input));
        EXPECT_LE(b.triangles_drawn, od.triangles_drawn)
            << s.name << ", seed " << seed << ", per pass " << per_pass;
      }
    }
}

TEST(GroupingBound, OnePassIsExact) {
  const int n = 10;
  const cpca::Geometry g = cpca_test::grid(n);
  const std::vector<std::uint32_t> cluster_of = grown_clusters(g, n, 5, 3);
  // Everything fits one pass: nothing is drawn twice.
  EXPECT_EQ(cpca::grouping_overdraw_bound({cluster_of, g.triangles, 5, 5}).triangles_drawn,
            g.triangles.size());
  EXPECT_THROW(cpca::grouping_overdraw_bound({cluster_of, g.triangles, 5, 0}),
               std::invalid_argument);
}

}  // namespace
