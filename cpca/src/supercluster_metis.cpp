// METIS 5 k-way partition of the cluster-adjacency graph, capacity repair and exact
// refinement.
#include "cpca/supercluster_metis.h"

#include "metis_kway.h"

#include "cpca/supercluster_refine.h"

#include <limits>
#include <numeric>
#include <stdexcept>
#include <string>
#include <vector>

namespace cpca {

namespace {

std::vector<std::uint32_t> metis_parts(const ClusterIncidence& inc, int parts, int seed) {
  KwayOptions o;
  o.parts = parts;
  o.seed = std::uint64_t(seed);
  o.imbalance = 1;  // 0.1%: as close to a hard capacity as it gets
  o.nodes = "clusters";
  o.advice = "try another strategy";
  return metis_kway({inc.neighbor_offset, inc.neighbor, inc.neighbor_weight, {}}, o);
}

// Moves clusters out of parts above capacity, each time the (cluster, part with room) pair
// whose move adds the fewest draws.
std::vector<std::uint32_t> repair_capacity(const ClusterIncidence& inc, int per_pass,
                                           std::vector<std::uint32_t> pass_of, int parts) {
  std::vector<int> size(std::size_t(parts), 0);
  for (std::uint32_t p : pass_of) ++size[p];
  // The local search computes exact move costs; overfull passes are fine for it as long as
  // its capacity is the current largest size.
  int largest = per_pass;
  for (int s : size) largest = std::max(largest, s);
  GroupingLocalSearch state(inc, largest, std::move(pass_of), parts);
  for (std::uint32_t p = 0; p < std::uint32_t(parts); ++p) {
    while (int(state.members(p).size()) > per_pass) {
      std::int64_t best = std::numeric_limits<std::int64_t>::max();
      std::uint32_t best_c = 0, best_q = 0;
      for (std::uint32_t c : state.members(p))
        for (std::uint32_t q = 0; q < std::uint32_t(parts); ++q)
          if (int(state.members(q).size()) < per_pass) {
            const std::int64_t d = state.delta_move(c, q);
            if (d < best) best = d, best_c = c, best_q = q;
          }
      state.move(best_c, best_q);  // a part with room exists: parts * per_pass >= K
    }
  }
  return state.pass_of();
}

}  // namespace

SuperClusters group_metis(const ClusterIncidence& inc, int per_pass, const MetisOptions& options) {
  const int k_count = inc.cluster_count;
  const int parts = (k_count + per_pass - 1) / per_pass;
  std::vector<std::uint32_t> pass_of(std::size_t(k_count), 0);
  if (parts == 1) return groups_from_pass_of(pass_of);
  if (per_pass == 1) {
    std::iota(pass_of.begin(), pass_of.end(), 0u);
    return groups_from_pass_of(pass_of);
  }
  pass_of = repair_capacity(inc, per_pass, metis_parts(inc, parts, options.seed), parts);
  if (!options.refine) return groups_from_pass_of(pass_of);
  GroupingLocalSearch search(inc, per_pass, std::move(pass_of), parts);
  search.descend_fully();
  return search.groups();
}

SuperClusters group_metis(const SuperClusterInput& input) {
  return group_metis(cluster_incidence(input), input.per_pass);
}

}  // namespace cpca
