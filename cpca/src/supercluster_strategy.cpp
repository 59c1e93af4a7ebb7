#include "cpca/supercluster_strategy.h"

#include "cpca/supercluster_greedy.h"
#include "cpca/supercluster_incidence.h"
#include "cpca/supercluster_metis.h"
#include "cpca/supercluster_refine.h"
#include "cpca/supercluster_search.h"

#include <array>
#include <stdexcept>

namespace cpca {

void validate(const SuperClusterInput& input) {
  if (input.cluster_count < 1)
    throw std::invalid_argument("super-clusters: cluster count " +
                                std::to_string(input.cluster_count) +
                                " must be >= 1 (pass the number of CPCA clusters)");
  if (input.per_pass < 1)
    throw std::invalid_argument("super-clusters: clusters per pass " +
                                std::to_string(input.per_pass) +
                                " must be >= 1 (raise the register budget)");
  for (std::size_t v = 0; v < input.cluster_of.size(); ++v)
    if (input.cluster_of[v] >= std::uint32_t(input.cluster_count))
      throw std::invalid_argument("super-clusters: vertex " + std::to_string(v) + " has cluster " +
                                  std::to_string(input.cluster_of[v]) + " >= cluster count " +
                                  std::to_string(input.cluster_count) +
                                  " (cluster ids and count disagree)");
  for (std::size_t t = 0; t < input.triangles.size(); ++t)
    for (std::uint32_t v : input.triangles[t])
      if (v >= input.cluster_of.size())
        throw std::invalid_argument("super-clusters: triangle " + std::to_string(t) +
                                    " uses vertex " + std::to_string(v) + " but only " +
                                    std::to_string(input.cluster_of.size()) +
                                    " vertices have a cluster (mesh and clustering disagree)");
}

int pass_count(const SuperClusterInput& input) {
  return (input.cluster_count + input.per_pass - 1) / input.per_pass;
}

void check_grouping(const SuperClusterInput& input, const SuperClusters& groups,
                    std::string_view strategy) {
  const auto fail = [&](const std::string& what) {
    throw std::logic_error("super-cluster strategy '" + std::string(strategy) + "': " + what);
  };
  if (int(groups.passes.size()) > pass_count(input))
    fail(std::to_string(groups.passes.size()) + " passes, more than the " +
         std::to_string(pass_count(input)) + " needed");
  for (std::size_t p = 0; p < groups.passes.size(); ++p)
    if (groups.passes[p].empty() || int(groups.passes[p].size()) > input.per_pass)
      fail("pass " + std::to_string(p) + " holds " + std::to_string(groups.passes[p].size()) +
           " clusters, capacity " + std::to_string(input.per_pass));
  std::vector<std::uint32_t> pass_of;
  try {
    pass_of = pass_of_clusters(groups, input.cluster_count);
  } catch (const std::invalid_argument& e) {
    fail(e.what());
  }
  if (pass_of != groups.pass_of) fail("pass_of disagrees with passes");
}

namespace {

SuperClusters run_order(const SuperClusterInput& input) {
  return group_in_order(input.cluster_count, input.per_pass);
}

SuperClusters run_greedy_refine(const SuperClusterInput& input) {
  const ClusterIncidence inc = cluster_incidence(input);
  return refine_grouping(inc, input.per_pass, group_greedy(inc, input.per_pass));
}

constexpr std::array<NamedStrategy, 5> kStrategies = {{
    {"order", "clusters in id order, per_pass to a pass (baseline)", run_order},
    {"greedy", "thesis Fig. 4.6: seed with the most vertices, add the best overdraw reducer",
     group_greedy},
    {"greedy-refine", "greedy, then exact moves/swaps to a local optimum", run_greedy_refine},
    {"metis", "METIS k-way on the cluster graph, capacity repair, exact moves/swaps", group_metis},
    {"ils", "best of greedy/METIS/random starts, then iterated local search (exact)", group_search},
}};

}  // namespace

std::span<const NamedStrategy> supercluster_strategies() {
  return kStrategies;
}

std::string supercluster_strategy_names() {
  std::string names;
  for (const NamedStrategy& s : kStrategies)
    names += (names.empty() ? "" : ", ") + std::string(s.name);
  return names;
}

const NamedStrategy& find_supercluster_strategy(std::string_view name) {
  for (const NamedStrategy& s : kStrategies)
    if (s.name == name) return s;
  throw std::invalid_argument("unknown super-cluster strategy '" + std::string(name) +
                              "'; valid names: " + supercluster_strategy_names());
}

SuperClusters group_clusters(std::string_view name, const SuperClusterInput& input) {
  const NamedStrategy& strategy = find_supercluster_strategy(name);
  validate(input);
  SuperClusters groups = strategy.run(input);
  check_grouping(input, groups, strategy.name);
  return groups;
}

}  // namespace cpca
