// METIS 5 k-way partition of the cluster-adjacency graph, capacity repair and exact
// refinement. METIS is included only here.
#include "cpca/supercluster_metis.h"

#include "cpca/supercluster_refine.h"

#include <metis.h>

#include <limits>
#include <numeric>
#include <stdexcept>
#include <string>
#include <vector>

namespace cpca {

namespace {

std::vector<std::uint32_t> metis_parts(const ClusterIncidence& inc, int parts, int seed) {
  idx_t vertices = inc.cluster_count, constraints = 1, nparts = parts, cut = 0;
  std::vector<idx_t> xadj(inc.neighbor_offset.begin(), inc.neighbor_offset.end());
  // METIS reads adjncy[0] even for a graph without edges; never hand it an empty buffer.
  std::vector<idx_t> adjncy(inc.neighbor.begin(), inc.neighbor.end());
  std::vector<idx_t> adjwgt(inc.neighbor_weight.begin(), inc.neighbor_weight.end());
  adjncy.push_back(0);
  adjwgt.push_back(0);
  std::vector<idx_t> part(std::size_t(vertices), 0);
  idx_t options[METIS_NOPTIONS];
  METIS_SetDefaultOptions(options);
  options[METIS_OPTION_NUMBERING] = 0;
  options[METIS_OPTION_SEED] = seed;
  options[METIS_OPTION_UFACTOR] = 1;  // 0.1% imbalance: as close to a hard capacity as it gets
  const int rc =
      METIS_PartGraphKway(&vertices, &constraints, xadj.data(), adjncy.data(), nullptr, nullptr,
                          adjwgt.data(), &nparts, nullptr, nullptr, options, &cut, part.data());
  if (rc != METIS_OK)
    throw std::runtime_error("METIS_PartGraphKway failed (code " + std::to_string(rc) + ") on " +
                             std::to_string(vertices) + " clusters into " + std::to_string(parts) +
                             " parts; try another strategy");
  return std::vector<std::uint32_t>(part.begin(), part.end());
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
