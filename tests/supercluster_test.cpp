// Super-cluster strategies (thesis ch. 4.3): hand-counted overdraw on hand-made meshes, the
// thesis's worked example (Fig. 4.7), capacity/coverage invariants on random inputs, refinement
// never worse than its start, and a brute-force oracle over all groupings of tiny cluster counts.
#include "cpca/supercluster.h"
#include "cpca/supercluster_greedy.h"
#include "cpca/supercluster_incidence.h"
#include "cpca/supercluster_metis.h"
#include "cpca/supercluster_refine.h"
#include "cpca/supercluster_search.h"
#include "cpca/supercluster_strategy.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <functional>
#include <random>
#include <string>
#include <vector>

namespace {

using cpca::SuperClusterInput;
using cpca::SuperClusters;
using cpca::TriangleIndices;

struct ClusteredMesh {
  std::vector<std::uint32_t> cluster_of;
  std::vector<TriangleIndices> triangles;
  int cluster_count = 0;
  SuperClusterInput input(int per_pass) const {
    return {cluster_of, triangles, cluster_count, per_pass};
  }
};

std::uint64_t drawn(const ClusteredMesh& m, const SuperClusters& g) {
  return cpca::overdraw(m.cluster_of, m.triangles, g).triangles_drawn;
}

// A strip of 8 quads (16 triangles): top vertices 0..8, bottom 9..17, column c's two
// vertices in cluster kColumnCluster[c]. Along the strip the clusters read 0 | 2 | 1 | 3, so
// id order pairs non-neighbours. Quads 1, 3, 5 straddle a cluster border (2 triangles each,
// 2 clusters each); the other 5 quads lie inside one cluster.
ClusteredMesh strip() {
  constexpr std::uint32_t kColumnCluster[9] = {0, 0, 2, 2, 1, 1, 3, 3, 3};
  ClusteredMesh m;
  m.cluster_count = 4;
  for (int row = 0; row < 2; ++row)
    for (std::uint32_t k : kColumnCluster) m.cluster_of.push_back(k);
  for (std::uint32_t c = 0; c < 8; ++c) {
    m.triangles.push_back({c, 9 + c, c + 1});
    m.triangles.push_back({c + 1, 9 + c, 10 + c});
  }
  return m;
}

TEST(SuperclusterStrategies, StripMatchesHandCount) {
  const ClusteredMesh m = strip();
  // Hand count, 2 clusters per pass. In order: passes {0,1}, {2,3}; every border quad joins
  // clusters of different passes: 10 * 1 + 6 * 2 = 22 draws. Best: {0,2}, {1,3}; only the
  // 2|1 border is split: 10 + 2 + 4 + 2 = 18. Greedy seeds with cluster 3 (6 vertices, the
  // most), adds its only neighbour 1 (pass 0), then seeds 0 (4 vertices, lower id than 2)
  // and adds 2 (pass 1). Passes are numbered in the order greedy fills them.
  for (const cpca::NamedStrategy& s : cpca::supercluster_strategies()) {
    const SuperClusters g = cpca::group_clusters(s.name, m.input(2));
    const std::uint64_t expected = s.name == "order" ? 22 : 18;
    EXPECT_EQ(drawn(m, g), expected) << s.name;
    EXPECT_DOUBLE_EQ(cpca::overdraw(m.cluster_of, m.triangles, g).average_overdraw,
                     double(expected) / 16.0)
        << s.name;
  }
  const SuperClusters greedy = cpca::group_clusters("greedy", m.input(2));
  ASSERT_EQ(greedy.passes.size(), 2u);
  EXPECT_EQ(greedy.passes[0], (std::vector<std::uint32_t>{1, 3}));
  EXPECT_EQ(greedy.passes[1], (std::vector<std::uint32_t>{0, 2}));
}

TEST(SuperclusterStrategies, TrianglePassCountsOnStrip) {
  const ClusteredMesh m = strip();
  const SuperClusters g = cpca::group_clusters("greedy", m.input(2));
  const std::vector<std::uint8_t> counts = cpca::triangle_pass_counts(m.cluster_of, m.triangles, g);
  ASSERT_EQ(counts.size(), 16u);
  for (std::size_t t = 0; t < 16; ++t)  // only quad 3 (triangles 6, 7), the 2|1 border, is split
    EXPECT_EQ(counts[t], (t == 6 || t == 7) ? 2 : 1) << "triangle " << t;
  const SuperClusters order = cpca::group_clusters("order", m.input(2));
  const std::vector<std::uint8_t> ordered =
      cpca::triangle_pass_counts(m.cluster_of, m.triangles, order);
  for (std::size_t t = 0; t < 16; ++t)
    EXPECT_EQ(ordered[t], (t / 2 == 1 || t / 2 == 3 || t / 2 == 5) ? 2 : 1) << "triangle " << t;
}

TEST(SuperclusterStrategies, ThreeClusterTriangleCountsDistinctPasses) {
  // One triangle over clusters 0, 1, 2 and one over 0, 0, 3. Passes {0,1}, {2,3}: the first
  // is drawn by both passes (2), the second too (2): 4. Passes {0,3}, {1,2}: 2 + 1 = 3.
  ClusteredMesh m;
  m.cluster_count = 4;
  m.cluster_of = {0, 1, 2, 0, 0, 3};
  m.triangles = {{0, 1, 2}, {3, 4, 5}};
  EXPECT_EQ(drawn(m, cpca::group_in_order(4, 2)), 4u);
  EXPECT_EQ(drawn(m, cpca::groups_from_pass_of({0, 1, 1, 0})), 3u);
  EXPECT_EQ(cpca::triangle_pass_counts(m.cluster_of, m.triangles, cpca::group_in_order(4, 1)),
            (std::vector<std::uint8_t>{3, 2}));
  // Greedy is myopic here: seeded with 0 (3 vertices), it sees a gain of 1 for each of 1, 2
  // and 3 (joining 1 to 0 does not yet save the 0-1-2 triangle's third pass), takes the tie's
  // lower id 1 and ends at 4 draws. The refining strategies find 3.
  for (const cpca::NamedStrategy& s : cpca::supercluster_strategies()) {
    const bool myopic = s.name == "order" || s.name == "greedy";
    EXPECT_EQ(drawn(m, cpca::group_clusters(s.name, m.input(2))), myopic ? 4u : 3u) << s.name;
  }
}

// Thesis Fig. 4.7: red (0) is the largest cluster; it shares 8 triangles with green (1),
// 5 with blue (2), 3 with purple (3); green and purple share `green_purple`. Each shared
// triangle has two vertices in the first cluster and one in the second; red also has 5
// triangles of its own.
ClusteredMesh worked_example(int green_purple) {
  ClusteredMesh m;
  m.cluster_count = 4;
  const auto add = [&m](std::uint32_t a, std::uint32_t b, std::uint32_t c) {
    const std::uint32_t v = std::uint32_t(m.cluster_of.size());
    m.cluster_of.insert(m.cluster_of.end(), {a, b, c});
    m.triangles.push_back({v, v + 1, v + 2});
  };
  for (int i = 0; i < 5; ++i) add(0, 0, 0);
  for (int i = 0; i < 8; ++i) add(0, 0, 1);
  for (int i = 0; i < 5; ++i) add(0, 0, 2);
  for (int i = 0; i < 3; ++i) add(0, 0, 3);
  for (int i = 0; i < green_purple; ++i) add(1, 1, 3);
  return m;
}

TEST(SuperclusterGreedy, ReproducesThesisWorkedExample) {
  // Seed red; green removes 8 draws (blue 5, purple 3) and joins; with green merged in,
  // purple removes 3 + 4 = 7 > blue's 5, so purple completes the pass of 3.
  const ClusteredMesh m = worked_example(4);
  const SuperClusters g = cpca::group_clusters("greedy", m.input(3));
  ASSERT_EQ(g.passes.size(), 2u);
  EXPECT_EQ(g.passes[0], (std::vector<std::uint32_t>{0, 1, 3}));
  EXPECT_EQ(g.passes[1], (std::vector<std::uint32_t>{2}));
  // Hand count: 25 triangles, only the 5 red-blue ones are drawn twice. Every alternative
  // with 3 per pass splits more ({0,1,2}|{3}: 7, {0,2,3}|{1}: 12, {1,2,3}|{0}: 16), so every
  // strategy except the id order must reach 30 draws; the id order ({0,1,2}|{3}) draws 32.
  for (const cpca::NamedStrategy& s : cpca::supercluster_strategies())
    EXPECT_EQ(drawn(m, cpca::group_clusters(s.name, m.input(3))), s.name == "order" ? 32u : 30u)
        << s.name;
}

TEST(SuperclusterGreedy, MergedReductionsDecide) {
  // Without the green-purple triangles, purple alone removes 3 < blue's 5: blue is taken.
  const ClusteredMesh m = worked_example(0);
  const SuperClusters g = cpca::group_clusters("greedy", m.input(3));
  EXPECT_EQ(g.passes[0], (std::vector<std::uint32_t>{0, 1, 2}));
}

// Random clustered grids: n x n vertices, clusters grown as Voronoi regions of random grid
// seeds (spatially coherent, like CPCA with geometry coherence), plus a few random
// triangles anywhere (like CPCA clusters scattered over the mesh).
ClusteredMesh random_mesh(std::uint32_t seed, int cluster_count) {
  std::mt19937 rng(seed);
  const int n = 6 + int(rng() % 20);
  ClusteredMesh m;
  m.cluster_count = cluster_count;
  std::vector<std::pair<int, int>> centres(static_cast<std::size_t>(cluster_count));
  for (auto& c : centres) c = {int(rng() % n), int(rng() % n)};
  for (int y = 0; y < n; ++y)
    for (int x = 0; x < n; ++x) {
      std::uint32_t best = 0;
      int best_d = 1 << 30;
      for (std::uint32_t k = 0; k < centres.size(); ++k) {
        const int d = (x - centres[k].first) * (x - centres[k].first) +
                      (y - centres[k].second) * (y - centres[k].second);
        if (d < best_d) best_d = d, best = k;
      }
      m.cluster_of.push_back(best);
    }
  for (int y = 0; y + 1 < n; ++y)
    for (int x = 0; x + 1 < n; ++x) {
      const std::uint32_t v = std::uint32_t(y * n + x), w = std::uint32_t(n);
      m.triangles.push_back({v, v + 1, v + w});
      m.triangles.push_back({v + 1, v + w + 1, v + w});
    }
  const int extra = int(rng() % 8);
  const std::uint32_t vertices = std::uint32_t(n * n);
  for (int i = 0; i < extra; ++i)
    m.triangles.push_back({std::uint32_t(rng() % vertices), std::uint32_t(rng() % vertices),
                           std::uint32_t(rng() % vertices)});
  return m;
}

// A random case for the local search: K = min_k + [0, k_span), per pass 2 + [0, pass_span),
// random_mesh of that K and its incidence, and the generator for the test's further draws.
struct RandomCase {
  std::mt19937 rng;
  int k = 0, per_pass = 0;
  ClusteredMesh mesh;
  cpca::ClusterIncidence inc;
};
RandomCase random_case(std::uint32_t seed, int min_k, int k_span, int pass_span) {
  RandomCase rc;
  rc.rng.seed(seed);
  rc.k = min_k + int(rc.rng() % std::uint32_t(k_span));
  rc.per_pass = 2 + int(rc.rng() % std::uint32_t(pass_span));
  rc.mesh = random_mesh(seed, rc.k);
  rc.inc = cpca::cluster_incidence(rc.mesh.input(rc.per_pass));
  return rc;
}

// Clusters grouped in id order, with one pass to spare so that moves are possible.
cpca::GroupingLocalSearch in_order_search(const RandomCase& rc) {
  return cpca::GroupingLocalSearch(rc.inc, rc.per_pass,
                                   cpca::group_in_order(rc.k, rc.per_pass).pass_of,
                                   (rc.k + rc.per_pass - 1) / rc.per_pass + 1);
}

TEST(SuperclusterStrategies, CapacityAndCoverageOnRandomInputs) {
  for (std::uint32_t seed = 0; seed < 60; ++seed) {
    std::mt19937 rng(seed * 7919u + 1u);
    const int k = 1 + int(rng() % 40);
    const int per_pass = 1 + int(rng() % std::uint32_t(k + 2));
    const ClusteredMesh m = random_mesh(seed, k);
    const cpca::ClusterIncidence inc = cpca::cluster_incidence(m.input(per_pass));
    for (const cpca::NamedStrategy& s : cpca::supercluster_strategies()) {
      SCOPED_TRACE(std::string(s.name) + " seed " + std::to_string(seed) + " K " +
                   std::to_string(k) + " per pass " + std::to_string(per_pass));
      const SuperClusters g = s.run(m.input(per_pass));  // unchecked, checked here
      std::vector<int> seen(std::size_t(k), 0);
      for (const auto& pass : g.passes) {
        EXPECT_GE(pass.size(), 1u);
        EXPECT_LE(int(pass.size()), per_pass);
        for (std::uint32_t c : pass) {
          ASSERT_LT(c, std::uint32_t(k));
          ++seen[c];
        }
      }
      for (int c = 0; c < k; ++c) EXPECT_EQ(seen[std::size_t(c)], 1) << "cluster " << c;
      EXPECT_EQ(int(g.passes.size()), (k + per_pass - 1) / per_pass);
      ASSERT_EQ(g.pass_of.size(), std::size_t(k));
      for (std::size_t p = 0; p < g.passes.size(); ++p)
        for (std::uint32_t c : g.passes[p]) EXPECT_EQ(g.pass_of[c], p);
      // The hyperedge count of every strategy's objective equals the triangle-level one.
      EXPECT_EQ(cpca::triangles_drawn(inc, g.pass_of), drawn(m, g));
    }
  }
}

TEST(SuperclusterStrategies, RefinementNeverWorseThanItsStart) {
  for (std::uint32_t seed = 0; seed < 60; ++seed) {
    const RandomCase rc = random_case(seed + 1000u, 4, 60, 6);
    const int per_pass = rc.per_pass;
    const ClusteredMesh& m = rc.mesh;
    const cpca::ClusterIncidence& inc = rc.inc;
    SCOPED_TRACE("seed " + std::to_string(seed));
    const std::uint64_t metis_raw = drawn(m, cpca::group_metis(inc, per_pass, {.refine = false}));
    const std::uint64_t metis = drawn(m, cpca::group_metis(inc, per_pass));
    const std::uint64_t greedy = drawn(m, cpca::group_greedy(inc, per_pass));
    const std::uint64_t greedy_refined =
        drawn(m, cpca::refine_grouping(inc, per_pass, cpca::group_greedy(inc, per_pass)));
    const std::uint64_t ils = drawn(m, cpca::group_search(inc, per_pass));
    EXPECT_LE(metis, metis_raw);
    EXPECT_LE(greedy_refined, greedy);
    EXPECT_LE(ils, greedy_refined);
    EXPECT_LE(ils, metis);
  }
}

TEST(SuperclusterRefine, FastDeltasMatchReferenceAndRecount) {
  // The pull table is updated incrementally; after every random step, each fast delta must
  // equal the hyperedge recount, and drawn() the full recount (all integers: exact).
  for (std::uint32_t seed = 0; seed < 20; ++seed) {
    RandomCase rc = random_case(seed + 500u, 3, 30, 4);
    std::mt19937& rng = rc.rng;
    const int k = rc.k, per_pass = rc.per_pass;
    const cpca::ClusterIncidence& inc = rc.inc;
    cpca::GroupingLocalSearch search = in_order_search(rc);
    const int passes = search.pass_count();
    for (int step = 0; step < 200; ++step) {
      const std::uint32_t c = std::uint32_t(rng() % std::uint32_t(k));
      const std::uint32_t d = std::uint32_t(rng() % std::uint32_t(k));
      const std::uint32_t q = std::uint32_t(rng() % std::uint32_t(passes));
      ASSERT_EQ(search.delta_move(c, q), search.delta_move_reference(c, q));
      ASSERT_EQ(search.delta_swap(c, d), search.delta_swap_reference(c, d));
      // The corrections descend() takes from one walk, for all of c's partners at once.
      std::vector<std::int64_t> correction(std::size_t(k), 0);
      search.shared_corrections(c, correction);
      for (std::uint32_t e = 0; e < std::uint32_t(k); ++e) {
        const std::uint32_t pc = search.pass_of()[c], pe = search.pass_of()[e];
        if (e == c || pc == pe) continue;
        ASSERT_EQ(
            search.delta_move_reference(c, pe) + search.delta_move_reference(e, pc) + correction[e],
            search.delta_swap_reference(c, e))
            << "seed " << seed << " step " << step << " partner " << e;
      }
      const std::uint64_t before = search.drawn();
      if (step % 2 == 0 && int(search.members(q).size()) < per_pass && search.pass_of()[c] != q) {
        const std::int64_t delta = search.delta_move(c, q);
        search.move(c, q);
        EXPECT_EQ(std::int64_t(search.drawn()) - std::int64_t(before), delta);
      } else if (search.pass_of()[c] != search.pass_of()[d]) {
        search.swap(c, d);
      }
      ASSERT_EQ(search.drawn(), cpca::triangles_drawn(inc, search.pass_of()))
          << "seed " << seed << " step " << step;
    }
  }
}

TEST(SuperclusterRefine, UndoneTrialRestoresTheSearchExactly) {
  // ILS runs each trial on its search and takes it back: after random moves, swaps and a
  // descent, undo_trial() must leave the state a copy taken before it holds, member order and
  // every pull-table delta included, and a kept trial must equal the same moves on a copy.
  for (std::uint32_t seed = 0; seed < 20; ++seed) {
    RandomCase rc = random_case(seed + 900u, 4, 30, 4);
    std::mt19937& rng = rc.rng;
    const int k = rc.k, per_pass = rc.per_pass;
    cpca::GroupingLocalSearch search = in_order_search(rc);
    const int passes = search.pass_count();
    for (int trial = 0; trial < 30; ++trial) {
      const cpca::GroupingLocalSearch before = search;
      cpca::GroupingLocalSearch replay = search;
      const bool keep = trial % 3 == 0;
      search.begin_trial();
      std::vector<std::uint32_t> touched;
      for (int step = 0; step < 1 + int(rng() % 4); ++step) {
        const std::uint32_t c = std::uint32_t(rng() % std::uint32_t(k));
        const std::uint32_t d = std::uint32_t(rng() % std::uint32_t(k));
        const std::uint32_t q = std::uint32_t(rng() % std::uint32_t(passes));
        if (int(search.members(q).size()) < per_pass && search.pass_of()[c] != q) {
          search.move(c, q);
          replay.move(c, q);
        } else if (search.pass_of()[c] != search.pass_of()[d]) {
          search.swap(c, d);
          replay.swap(c, d);
        }
        touched.push_back(c);
      }
      search.descend(touched);
      replay.descend(touched);
      if (keep) {
        search.end_trial();
      } else {
        search.undo_trial();
      }
      const cpca::GroupingLocalSearch& expect = keep ? replay : before;
      ASSERT_EQ(search.drawn(), expect.drawn()) << "seed " << seed << " trial " << trial;
      ASSERT_EQ(search.pass_of(), expect.pass_of());
      for (std::uint32_t p = 0; p < std::uint32_t(passes); ++p)
        ASSERT_EQ(search.members(p), expect.members(p)) << "pass " << p;
      for (std::uint32_t c = 0; c < std::uint32_t(k); ++c)
        for (std::uint32_t q = 0; q < std::uint32_t(passes); ++q)
          ASSERT_EQ(search.delta_move(c, q), expect.delta_move(c, q));
    }
  }
  const cpca::ClusterIncidence strip_incidence = cpca::cluster_incidence(strip().input(2));
  cpca::GroupingLocalSearch idle(strip_incidence, 2, cpca::group_in_order(4, 2).pass_of, 2);
  EXPECT_THROW(idle.undo_trial(), std::logic_error);
}

TEST(SuperclusterStrategies, OnePassDrawsEveryTriangleOnce) {
  for (std::uint32_t seed = 0; seed < 10; ++seed) {
    const int k = 1 + int(seed * 3);
    const ClusteredMesh m = random_mesh(seed + 77u, k);
    for (int per_pass : {k, k + 5})
      for (const cpca::NamedStrategy& s : cpca::supercluster_strategies()) {
        const SuperClusters g = cpca::group_clusters(s.name, m.input(per_pass));
        EXPECT_EQ(g.passes.size(), 1u) << s.name;
        EXPECT_EQ(cpca::overdraw(m.cluster_of, m.triangles, g).average_overdraw, 1.0) << s.name;
      }
  }
}

// Every grouping of k clusters into blocks of <= per_pass (set partitions, restricted
// growth strings); calls visit(pass_of, block count).
void for_each_grouping(int k, int per_pass,
                       const std::function<void(const std::vector<std::uint32_t>&, int)>& visit) {
  std::vector<std::uint32_t> pass_of(std::size_t(k), 0);
  std::vector<int> size(std::size_t(k), 0);
  std::function<void(int, int)> place = [&](int c, int blocks) {
    if (c == k) return visit(pass_of, blocks);
    for (int b = 0; b <= blocks && b < k; ++b) {
      if (size[std::size_t(b)] >= per_pass) continue;
      pass_of[std::size_t(c)] = std::uint32_t(b);
      ++size[std::size_t(b)];
      place(c + 1, std::max(blocks, b + 1));
      --size[std::size_t(b)];
    }
  };
  place(0, 0);
}

TEST(SuperclusterOracle, TinyClusterCountsAgainstBruteForce) {
  // Tolerance: this measures how close the best strategy gets to the optimum; on these
  // sizes iterated local search is expected to be exact, so any gap fails. Greedy's and
  // METIS's gaps are printed as the report's figures, not asserted.
  double worst_greedy = 0.0, worst_metis = 0.0;
  int fewer_passes_win = 0, cases = 0;
  for (int k : {6, 7, 8})
    for (int per_pass : {2, 3})
      for (std::uint32_t seed = 0; seed < 15; ++seed) {
        const ClusteredMesh m = random_mesh(seed * 31u + std::uint32_t(k * 7 + per_pass), k);
        const cpca::ClusterIncidence inc = cpca::cluster_incidence(m.input(per_pass));
        const int min_passes = (k + per_pass - 1) / per_pass;
        std::uint64_t best_min = ~0ull, best_any = ~0ull;
        for_each_grouping(k, per_pass, [&](const std::vector<std::uint32_t>& pass_of, int blocks) {
          const std::uint64_t d = cpca::triangles_drawn(inc, pass_of);
          best_any = std::min(best_any, d);
          if (blocks == min_passes) best_min = std::min(best_min, d);
        });
        // Fewer passes can be forced to cost more than extra passes would (the pass count
        // is fixed at the minimum by design); count how often.
        fewer_passes_win += best_any < best_min;
        ++cases;
        const std::uint64_t ils = drawn(m, cpca::group_search(inc, per_pass));
        EXPECT_EQ(ils, best_min) << "K " << k << " per pass " << per_pass << " seed " << seed;
        const double triangles = double(m.triangles.size());
        worst_greedy =
            std::max(worst_greedy, double(drawn(m, cpca::group_greedy(inc, per_pass))) / triangles -
                                       double(best_min) / triangles);
        worst_metis =
            std::max(worst_metis, double(drawn(m, cpca::group_metis(inc, per_pass))) / triangles -
                                      double(best_min) / triangles);
      }
  std::printf(
      "[ oracle   ] %d cases: worst overdraw gap to optimum: greedy %.4f, metis %.4f, ils 0 "
      "by assertion; optimum with more passes beats minimum passes in %d cases\n",
      cases, worst_greedy, worst_metis, fewer_passes_win);
}

TEST(SuperclusterStrategies, ErrorsNameTheFix) {
  const ClusteredMesh m = strip();
  try {
    cpca::group_clusters("kmeans", m.input(2));
    FAIL() << "unknown name accepted";
  } catch (const std::invalid_argument& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("kmeans"), std::string::npos) << what;
    for (const cpca::NamedStrategy& s : cpca::supercluster_strategies())
      EXPECT_NE(what.find(s.name), std::string::npos) << what;
  }
  EXPECT_THROW(cpca::group_clusters("greedy", m.input(0)), std::invalid_argument);
  ClusteredMesh bad = m;
  bad.cluster_count = 3;  // cluster 3 is used by vertices
  EXPECT_THROW(cpca::group_clusters("greedy", bad.input(2)), std::invalid_argument);
  bad = m;
  bad.triangles.push_back({0, 1, 99});
  EXPECT_THROW(cpca::group_clusters("metis", bad.input(2)), std::invalid_argument);
  // check_grouping catches a strategy that overfills a pass.
  EXPECT_THROW(cpca::check_grouping(m.input(2), cpca::group_in_order(4, 3), "test"),
               std::logic_error);
}

}  // namespace
