// cpca/supercluster_strategy.h: one interface for super-cluster strategies and a registry of
// them by name, so the CLI and the benchmark can loop over all of them
// (prtr overdraw compares them; thesis ch. 4.3).
//
// A strategy groups `cluster_count` clusters into passes of at most `per_pass` clusters,
// every cluster in exactly one pass, trying to keep the exact triangle overdraw low
// (cpca/supercluster.h: sum over triangles of the distinct passes among its vertices'
// clusters / triangle count). Strategies never open more passes than needed,
// ceil(cluster_count / per_pass): splitting a pass never lowers any triangle's draw count,
// so the minimum pass count is also what a renderer wants.
#pragma once

#include "cpca/supercluster.h"

#include <cstdint>
#include <span>
#include <string>
#include <string_view>

namespace cpca {

struct SuperClusterInput {
  std::span<const std::uint32_t> cluster_of;   // cluster of each vertex, < cluster_count
  std::span<const TriangleIndices> triangles;  // vertex indices, < cluster_of.size()
  int cluster_count = 0;                       // >= 1; clusters without vertices are allowed
  int per_pass = 1;                            // clusters per pass (render::pass_capacity), >= 1
};

// Throws std::invalid_argument naming the offending field and the fix.
void validate(const SuperClusterInput& input);

// The fewest passes that hold every cluster: ceil(cluster_count / per_pass).
int pass_count(const SuperClusterInput& input);

// Always-on check of a strategy's result: every pass holds 1..per_pass clusters, every
// cluster is in exactly one pass, pass_of agrees with passes. Throws std::logic_error naming
// `strategy` and the broken invariant (a bug in the strategy, not bad input).
void check_grouping(const SuperClusterInput& input, const SuperClusters& groups,
                    std::string_view strategy);

using SuperClusterStrategy = SuperClusters (*)(const SuperClusterInput&);

struct NamedStrategy {
  std::string_view name;
  std::string_view summary;  // one line for --help and benchmark legends
  SuperClusterStrategy run;
};

// Every registered strategy, in a fixed order (baseline first).
std::span<const NamedStrategy> supercluster_strategies();

// "order, greedy, ..." for messages.
std::string supercluster_strategy_names();

// The strategy called `name`; throws std::invalid_argument listing the valid names.
const NamedStrategy& find_supercluster_strategy(std::string_view name);

// Validates the input, runs the named strategy and checks its result.
SuperClusters group_clusters(std::string_view name, const SuperClusterInput& input);

}  // namespace cpca
