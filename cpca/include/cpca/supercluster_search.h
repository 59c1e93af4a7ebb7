// cpca/supercluster_search.h: our strongest super-cluster strategy ("ils"): several starts
// (the thesis's greedy, METIS + refinement, greedy with random seed priorities), each driven
// to a local optimum of the exact overdraw, then iterated local search from the best one.
//
// Iterated local search: kick the current grouping with 1-3 random swaps/moves between a
// cluster and a neighbouring pass, descend again (cpca/supercluster_refine.h), keep the
// result if it draws no more triangles than before (equal moves let it walk plateaus), else
// undo. The RNG is seeded, so the result is deterministic; it is never worse than any start.
#pragma once

#include "cpca/supercluster_incidence.h"

#include <cstdint>

namespace cpca {

struct SearchOptions {
  int random_starts = 4;       // randomised greedy starts besides greedy and METIS
  int kicks_per_cluster = 20;  // ILS iterations = kicks_per_cluster * K
  std::uint64_t seed = 0x5eed;
};

SuperClusters group_search(const SuperClusterInput& input);
SuperClusters group_search(const ClusterIncidence& incidence, int per_pass,
                           const SearchOptions& options = {});

}  // namespace cpca
