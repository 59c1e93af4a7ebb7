// The joint search over vertex -> cluster and cluster -> pass: with lambda = 0 it is
// iterative CPCA; its objective never rises and ends at what an independent recount of the
// returned set gives; the draws it tracks equal a brute-force count; the pass profile is
// the order grouping's.
#include "cpca/joint_search.h"

#include "cpca/cluster_pca.h"
#include "cpca/compress.h"

#include "cpca/supercluster_strategy.h"
#include "cpca_test_support.h"

#include <gtest/gtest.h>

#include <map>
#include <numeric>
#include <random>
#include <set>

namespace {

const int kN = 20, kClusters = 14, kPerPass = 3;

// Smooth transfer over a grid plus noise: clusters by signal are spatially patchy, so the
// error-only clustering has real overdraw to trade.
cpca::DataMatrix smooth_data(const cpca::Geometry& g, unsigned seed) {
  std::mt19937 rng(seed);
  std::normal_distribution<float> noise(0.f, 0.05f);
  cpca::DataMatrix x(Eigen::Index(g.positions.size()), 9);
  for (std::size_t p = 0; p < g.positions.size(); ++p)
    for (int i = 0; i < 9; ++i)
      x(Eigen::Index(p), i) = std::sin(float(i + 2) * g.positions[p].x() + float(i)) *
                                  std::cos(float(7 - i % 5) * g.positions[p].y()) +
                              noise(rng);
  return x;
}

cpca::CompressOptions options(cpca::ClusterMethod method, double lambda) {
  cpca::CompressOptions o;
  o.layout = {3, 1, 1};
  o.clusters = kClusters;
  o.components = 2;
  o.method = method;
  o.clusters_per_pass = kPerPass;
  o.lambda = lambda;
  o.cpca_candidates = 4;
  return o;
}

std::uint64_t brute_force_draws(const std::vector<std::uint32_t>& cluster_of,
                                const std::vector<cpca::TriangleIndices>& triangles) {
  std::uint64_t drawn = 0;
  for (const cpca::TriangleIndices& t : triangles)
    drawn += std::set<std::uint32_t>{cluster_of[t[0]] / kPerPass, cluster_of[t[1]] / kPerPass,
                                     cluster_of[t[2]] / kPerPass}
                 .size();
  return drawn;
}

TEST(JointSearch, LambdaZeroIsIterativeCpca) {
  const cpca::Geometry g = cpca_test::grid(kN);
  const cpca::DataMatrix x = smooth_data(g, 3);
  const cpca::CompressedSet iterative =
      cpca::compress(x, options(cpca::ClusterMethod::kIterative, 0), &g);
  cpca::JointSearchResult search;
  const cpca::CompressedSet joint =
      cpca::compress_joint(x, options(cpca::ClusterMethod::kJoint, 0), g, nullptr, &search);
  ASSERT_GE(search.steps, 1);  // the comparison means something only if the search moved
  // The same partition under the pass renumbering, and the same numbers.
  std::map<std::uint32_t, std::uint32_t> map;
  for (std::size_t p = 0; p < joint.cluster_of.size(); ++p) {
    const auto [it, fresh] = map.emplace(joint.cluster_of[p], iterative.cluster_of[p]);
    ASSERT_EQ(it->second, iterative.cluster_of[p]) << "vertex " << p;
  }
  EXPECT_EQ(map.size(), std::size_t(kClusters));
  EXPECT_EQ(joint.weights, iterative.weights);
  EXPECT_EQ(cpca::error_metrics(x, joint).average_squared_error,
            cpca::error_metrics(x, iterative).average_squared_error);
  EXPECT_EQ(joint.iterations, iterative.iterations);
}

TEST(JointSearch, ObjectiveNeverRisesAndMatchesARecount) {
  const cpca::Geometry g = cpca_test::grid(kN);
  const cpca::DataMatrix x = smooth_data(g, 5);
  for (const auto method : {cpca::ClusterMethod::kJoint, cpca::ClusterMethod::kPatchJoint})
    for (double lambda : {0.05, 0.5, 5.0}) {
      SCOPED_TRACE(std::string(cpca::kClusterMethodNames.name(method)) + " " +
                   std::to_string(lambda));
      cpca::JointSearchResult search;
      const cpca::CompressedSet set =
          cpca::compress_joint(x, options(method, lambda), g, nullptr, &search);
      ASSERT_NO_THROW(cpca::validate(set));
      ASSERT_GE(search.objective.size(), 2u);
      for (std::size_t i = 1; i < search.objective.size(); ++i)
        EXPECT_LE(search.objective[i], search.objective[i - 1]) << "stage " << i;
      EXPECT_LT(search.objective.back(), search.objective.front());
      // The tracked draws against a brute-force count and against cpca::overdraw.
      const std::uint64_t drawn = brute_force_draws(set.cluster_of, g.triangles);
      EXPECT_EQ(search.triangles_drawn, drawn);
      EXPECT_EQ(
          cpca::overdraw(set.cluster_of, g.triangles, cpca::group_in_order(kClusters, kPerPass))
              .triangles_drawn,
          drawn);
      // J recomputed from the returned set by reconstruction (float round-off only).
      const double recount =
          cpca::error_metrics(x, set).average_squared_error +
          lambda * search.error_scale * double(drawn) / double(g.triangles.size());
      EXPECT_NEAR(search.objective.back(), recount, 1e-5 * recount);
    }
}

// The search refits only the clusters a step changed: the result must still be what a PCA
// fit of every cluster of the returned membership gives.
TEST(JointSearch, PartialRefitsEqualAFullFit) {
  const cpca::Geometry g = cpca_test::grid(kN);
  const cpca::DataMatrix x = smooth_data(g, 7);
  for (const auto method : {cpca::ClusterMethod::kJoint, cpca::ClusterMethod::kPatchJoint}) {
    cpca::JointSearchResult search;
    const cpca::CompressOptions o = options(method, 0.5);
    const cpca::CompressedSet set = cpca::compress_joint(x, o, g, nullptr, &search);
    ASSERT_GE(search.steps, 2);  // at least one step refitted from an earlier partial state
    cpca::CompressedSet full = set;
    cpca::PowerIterationOptions power;
    power.seed = o.seed;
    cpca::fit_cluster_pca(x, full, o.solver, power);
    EXPECT_EQ(full.means, set.means);
    EXPECT_EQ(full.bases, set.bases);
    EXPECT_EQ(full.weights, set.weights);
  }
}

TEST(JointSearch, LargerLambdaDrawsFewerTriangles) {
  const cpca::Geometry g = cpca_test::grid(kN);
  const cpca::DataMatrix x = smooth_data(g, 9);
  cpca::JointSearchResult low, high;
  cpca::compress_joint(x, options(cpca::ClusterMethod::kJoint, 0.01), g, nullptr, &low);
  cpca::compress_joint(x, options(cpca::ClusterMethod::kJoint, 10.0), g, nullptr, &high);
  EXPECT_LT(high.triangles_drawn, low.triangles_drawn);
}

// With a small lambda the search buys error with overdraw; a cap holds the overdraw at or
// below it (brute-force count) while J still never rises, and the error stays below the
// start's.
TEST(JointSearch, OverdrawCapBoundsTheDraws) {
  const cpca::Geometry g = cpca_test::grid(kN);
  const cpca::DataMatrix x = smooth_data(g, 11);
  cpca::CompressOptions o = options(cpca::ClusterMethod::kPatchJoint, 0.01);
  cpca::JointSearchResult free_search;
  cpca::compress_joint(x, o, g, nullptr, &free_search);
  const double free_overdraw = double(free_search.triangles_drawn) / double(g.triangles.size());
  cpca::JointSearchResult first;
  o.overdraw_cap = 1.0;  // the tightest cap there is
  cpca::compress_joint(x, o, g, nullptr, &first);
  const double floor_overdraw = double(first.triangles_drawn) / double(g.triangles.size());
  // A cap halfway between what the capped and the free searches reach must bind.
  const double cap = 0.5 * (floor_overdraw + free_overdraw);
  ASSERT_LT(floor_overdraw, cap);
  cpca::JointSearchResult capped;
  o.overdraw_cap = cap;
  const cpca::CompressedSet set = cpca::compress_joint(x, o, g, nullptr, &capped);
  const std::uint64_t drawn = brute_force_draws(set.cluster_of, g.triangles);
  EXPECT_EQ(capped.triangles_drawn, drawn);
  EXPECT_LE(double(drawn), cap * double(g.triangles.size()));
  EXPECT_LT(drawn, free_search.triangles_drawn);
  for (std::size_t i = 1; i < capped.objective.size(); ++i)
    EXPECT_LE(capped.objective[i], capped.objective[i - 1]) << "stage " << i;
  o.overdraw_cap = 0.5;
  EXPECT_THROW(cpca::compress_joint(x, o, g), std::invalid_argument);
}

// The epsilon search's constraint holds to the precision of its refits (power iteration to
// 1e-6, on float bases), not to the last bit of an independently computed original.
constexpr double kRefitTolerance = 1e-6;

// patch-eps: the Average SE ends at or below (1 + eps) x original CPCA's (LBG + PCA, same K
// and seed, compressed here independently) for several eps, and the draws it tracks are the
// brute-force count. Where the start (patch-first) already meets the constraint the search
// may only cut draws; where a reference below the start's error is given, it buys error back.
TEST(EpsilonSearch, MeetsTheErrorConstraint) {
  const cpca::Geometry g = cpca_test::grid(kN);
  const cpca::DataMatrix x = smooth_data(g, 5);
  cpca::CompressOptions lbg = options(cpca::ClusterMethod::kLbg, 0);
  cpca::CompressReport original;
  const std::vector<std::uint32_t> reference_clusters =
      cpca::compress(x, lbg, nullptr, &original).cluster_of;
  const double reference = original.error.average_squared_error;
  ASSERT_GT(reference, 0);
  cpca::CompressOptions first = options(cpca::ClusterMethod::kPatchFirst, 0);
  cpca::CompressReport start;
  const cpca::CompressedSet start_set = cpca::compress(x, first, &g, &start);
  const std::uint64_t start_draws = brute_force_draws(start_set.cluster_of, g.triangles);
  for (double eps : {0.0, 0.1, 0.5}) {
    SCOPED_TRACE("eps " + std::to_string(eps));
    cpca::CompressOptions o = options(cpca::ClusterMethod::kPatchEpsilon, 0);
    o.error_slack = eps;
    cpca::JointSearchResult search;
    cpca::CompressReport report;
    const cpca::CompressedSet set = cpca::compress_joint(x, o, g, &report, &search);
    EXPECT_EQ(set.method, cpca::ClusterMethod::kPatchEpsilon);
    EXPECT_LE(report.error.average_squared_error, (1 + eps) * reference * (1 + kRefitTolerance));
    EXPECT_EQ(search.triangles_drawn, brute_force_draws(set.cluster_of, g.triangles));
    if (start.error.average_squared_error <= (1 + eps) * reference) {
      EXPECT_LE(search.triangles_drawn, start_draws);
    }
    // The given reference (error and clusters) is the same constraint and the same patch
    // weights as the one computed inside; an error without its clusters is refused.
    o.error_target = reference;
    EXPECT_THROW(cpca::compress_joint(x, o, g), std::invalid_argument);
    o.reference_clusters = reference_clusters;
    const cpca::CompressedSet again = cpca::compress_joint(x, o, g);
    EXPECT_EQ(again.cluster_of, set.cluster_of);
  }
  // A reference below the start's error (7% below; iterative CPCA from LBG ends 14% above
  // the start on this data): the search has to lower the error below its start.
  cpca::CompressOptions o = options(cpca::ClusterMethod::kPatchEpsilon, 0);
  o.error_target = 0.93 * start.error.average_squared_error;
  o.reference_clusters = reference_clusters;
  cpca::JointSearchResult search;
  cpca::CompressReport report;
  const cpca::CompressedSet set = cpca::compress_joint(x, o, g, &report, &search);
  EXPECT_LE(report.error.average_squared_error, o.error_target * (1 + kRefitTolerance));
  EXPECT_EQ(search.triangles_drawn, brute_force_draws(set.cluster_of, g.triangles));
}

// Patches of a few vertices for their clusters (a small mesh at a large K, like the horse at
// K = 256): the constraint still holds, through the fallback start from original CPCA.
TEST(EpsilonSearch, HoldsWhenPatchesAreTooSmall) {
  const cpca::Geometry g = cpca_test::grid(12);
  const cpca::DataMatrix x = smooth_data(g, 3);
  for (int k : {36, 48}) {
    SCOPED_TRACE("K " + std::to_string(k));
    cpca::CompressOptions lbg = options(cpca::ClusterMethod::kLbg, 0);
    lbg.clusters = k;
    cpca::CompressReport original;
    cpca::compress(x, lbg, nullptr, &original);
    cpca::CompressOptions o = options(cpca::ClusterMethod::kPatchEpsilon, 0);
    o.clusters = k;
    cpca::CompressReport report;
    cpca::JointSearchResult search;
    const cpca::CompressedSet set = cpca::compress_joint(x, o, g, &report, &search);
    // To the refits' tolerance: the fallback refits the original's clusters by power
    // iteration to 1e-6, so its error may differ from LBG's own fit in the eighth digit (the
    // sanitizer build's -O1 rounding showed 1e-8).
    EXPECT_LE(report.error.average_squared_error,
              original.error.average_squared_error * (1 + kRefitTolerance));
    EXPECT_EQ(search.triangles_drawn, brute_force_draws(set.cluster_of, g.triangles));
  }
}

// A cap no step can reach (a tenth of the start's error): the search stops once its excess,
// falling at its last rate, could not reach zero in the steps left, and leaves a valid state
// whose draws are still counted right.
TEST(EpsilonSearch, GivesUpOnACapItCannotReach) {
  const cpca::Geometry g = cpca_test::grid(kN);
  const cpca::DataMatrix x = smooth_data(g, 5);
  cpca::CompressOptions o = options(cpca::ClusterMethod::kLbg, 0);
  cpca::CompressedSet set = cpca::compress(x, o);
  cpca::PowerIterationOptions power;
  power.seed = o.seed;
  std::vector<double> error = cpca::fit_cluster_pca(x, set, o.solver, power);
  const double start = std::accumulate(error.begin(), error.end(), 0.0) / double(x.rows());
  std::vector<std::uint32_t> pass_of(kClusters);
  for (std::uint32_t c = 0; c < kClusters; ++c) pass_of[c] = c / kPerPass;
  cpca::JointSearchOptions jo;
  jo.per_pass = kPerPass;
  jo.max_steps = 20;
  jo.error_target = 0.1 * start;
  const cpca::JointSearchResult r = cpca::joint_search(x, g, set, error, pass_of, jo);
  EXPECT_TRUE(r.gave_up);
  EXPECT_LT(r.tried, jo.max_steps);
  std::uint64_t drawn = 0;
  for (const cpca::TriangleIndices& t : g.triangles)
    drawn +=
        std::set<std::uint32_t>{r.pass_of[set.cluster_of[t[0]]], r.pass_of[set.cluster_of[t[1]]],
                                r.pass_of[set.cluster_of[t[2]]]}
            .size();
  EXPECT_EQ(r.triangles_drawn, drawn);
  // A reachable cap (the start's own error) is never given up on.
  cpca::CompressedSet again = cpca::compress(x, o);
  std::vector<double> again_error = cpca::fit_cluster_pca(x, again, o.solver, power);
  jo.error_target = start;
  EXPECT_FALSE(cpca::joint_search(x, g, again, again_error, pass_of, jo).gave_up);
}

TEST(EpsilonSearch, DeterministicForASeed) {
  const cpca::Geometry g = cpca_test::grid(kN);
  const cpca::DataMatrix x = smooth_data(g, 9);
  cpca::CompressOptions o = options(cpca::ClusterMethod::kPatchEpsilon, 0);
  o.error_slack = 0.05;
  const cpca::CompressedSet a = cpca::compress(x, o, &g);
  const cpca::CompressedSet b = cpca::compress(x, o, &g);
  EXPECT_EQ(a.cluster_of, b.cluster_of);
  EXPECT_EQ(a.means, b.means);
  EXPECT_EQ(a.bases, b.bases);
  EXPECT_EQ(a.weights, b.weights);
  o.error_slack = -0.1;
  EXPECT_THROW(cpca::compress(x, o, &g), std::invalid_argument);
}

// Distances carried from step to step (to clusters no kept step refitted since) against
// every distance computed afresh: the same search, step for step. Both from a start above the
// cap (patch-first's clusters, the closures' distances) so both kinds of step are taken.
TEST(EpsilonSearch, ReusedDistancesEqualFreshOnes) {
  const cpca::Geometry g = cpca_test::grid(kN);
  const cpca::DataMatrix x = smooth_data(g, 5);
  cpca::CompressOptions first = options(cpca::ClusterMethod::kPatchFirst, 0);
  cpca::CompressedSet start = cpca::compress(x, first, &g);
  cpca::PowerIterationOptions power;
  power.seed = first.seed;
  std::vector<double> start_error = cpca::fit_cluster_pca(x, start, first.solver, power);
  const double total = std::accumulate(start_error.begin(), start_error.end(), 0.0);
  std::vector<std::uint32_t> pass_of(kClusters);
  for (std::uint32_t c = 0; c < kClusters; ++c) pass_of[c] = c / kPerPass;
  cpca::JointSearchOptions jo;
  jo.per_pass = kPerPass;
  jo.candidates = 4;
  jo.error_target = 0.97 * total / double(x.rows());
  const auto search = [&](bool reuse, cpca::CompressedSet& set, std::vector<double>& error) {
    set = start, error = start_error;
    jo.reuse_distances = reuse;
    return cpca::joint_search(x, g, set, error, pass_of, jo);
  };
  cpca::CompressedSet reused, fresh;
  std::vector<double> reused_error, fresh_error;
  const cpca::JointSearchResult a = search(true, reused, reused_error);
  const cpca::JointSearchResult b = search(false, fresh, fresh_error);
  ASSERT_GT(a.steps, 2);
  EXPECT_EQ(a.tried, b.tried);
  EXPECT_EQ(a.steps, b.steps);
  EXPECT_EQ(a.triangles_drawn, b.triangles_drawn);
  EXPECT_EQ(a.pass_of, b.pass_of);
  EXPECT_EQ(reused.cluster_of, fresh.cluster_of);
  ASSERT_EQ(a.objective.size(), b.objective.size());
  for (std::size_t i = 0; i < a.objective.size(); ++i)
    EXPECT_NEAR(a.objective[i], b.objective[i], 1e-9 * b.objective[i]) << "step " << i;
  // The first step starts above the cap, and a later one is within it.
  EXPECT_GT(total, jo.error_target * double(x.rows()));
  EXPECT_LE(std::accumulate(fresh_error.begin(), fresh_error.end(), 0.0),
            jo.error_target * double(x.rows()) * (1 + kRefitTolerance));
}

TEST(JointSearch, OrderProfilePutsTheRoomInTheLastPass) {
  const cpca::Geometry g = cpca_test::grid(6);
  std::vector<std::uint32_t> cluster_of(g.positions.size());
  for (std::size_t p = 0; p < cluster_of.size(); ++p) cluster_of[p] = std::uint32_t(p % 10);
  cpca::SuperClusters groups;
  groups.passes = {{0, 1}, {2, 3, 4}, {5, 6}, {7, 8, 9}};
  groups.pass_of = cpca::pass_of_clusters(groups, 10);
  const std::vector<std::uint32_t> pass_of =
      cpca::order_profile(cluster_of, g.triangles, groups, 10, 3);
  std::vector<int> size(4, 0);
  for (std::uint32_t p : pass_of) ++size[p];
  EXPECT_EQ(size, (std::vector<int>{3, 3, 3, 1}));
}

TEST(JointSearch, RefusesBadParameters) {
  const cpca::Geometry g = cpca_test::grid(kN);
  const cpca::DataMatrix x = smooth_data(g, 1);
  EXPECT_THROW(cpca::compress_joint(x, options(cpca::ClusterMethod::kJoint, -1), g),
               std::invalid_argument);
  cpca::CompressOptions o = options(cpca::ClusterMethod::kJoint, 1);
  o.alpha = 0.05;
  EXPECT_THROW(cpca::compress(x, o, &g), std::invalid_argument);
  o.alpha = 0;
  EXPECT_THROW(cpca::compress(x, o), std::invalid_argument);  // no mesh
}

}  // namespace
