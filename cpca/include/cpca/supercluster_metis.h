// cpca/supercluster_metis.h: super-clusters from a graph partitioner (METIS 5, k-way) on the
// cluster-adjacency graph weighted by shared triangles (one of the strategies
// prtr overdraw compares).
//
// Parts = ceil(K / per_pass), unit vertex weights. METIS balances only approximately, so
// overfull parts are repaired by moving, one at a time, the cluster whose move to a part with
// room costs the fewest extra draws (exact); then, unless disabled, the grouping is refined
// by the exact local search of cpca/supercluster_refine.h. METIS_PartGraphKway needs at
// least 2 parts, so 1 part (everything fits one pass) and per_pass = 1 (one cluster per
// pass, nothing to choose) are answered directly.
#pragma once

#include "cpca/supercluster_incidence.h"

#include <cstdint>

namespace cpca {

struct MetisOptions {
  bool refine = true;
  int seed = 1;  // METIS's RNG seed: fixed, so the same input gives the same grouping
};

SuperClusters group_metis(const SuperClusterInput& input);
SuperClusters group_metis(const ClusterIncidence& incidence, int per_pass,
                          const MetisOptions& options = {});

}  // namespace cpca
