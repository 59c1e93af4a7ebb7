// Thesis §4.3, Fig. 4.6: greedy super-cluster selection. See cpca/supercluster_greedy.h.
#include "cpca/supercluster_greedy.h"

#include <algorithm>
#include <numeric>

namespace cpca {

SuperClusters group_greedy(const ClusterIncidence& inc, int per_pass,
                           const std::vector<std::uint64_t>* rank) {
  const std::size_t k_count = std::size_t(inc.cluster_count);
  std::vector<std::uint64_t> priority(k_count);
  for (std::size_t k = 0; k < k_count; ++k) priority[k] = rank ? (*rank)[k] : inc.vertex_count[k];
  // a before b: higher priority, then lower id.
  const auto before = [&](std::uint32_t a, std::uint32_t b) {
    return priority[a] != priority[b] ? priority[a] > priority[b] : a < b;
  };
  std::vector<std::uint32_t> seed_order(k_count);
  std::iota(seed_order.begin(), seed_order.end(), 0u);
  std::sort(seed_order.begin(), seed_order.end(), before);

  std::vector<std::uint32_t> pass_of(k_count, ClusterHyperedge::kNone);
  std::vector<std::uint64_t> gain(k_count, 0);
  std::vector<char> touched(inc.hyperedges.size(), 0);  // hyperedge has a cluster of C
  std::vector<std::uint32_t> touched_list, gained_list;
  std::vector<std::uint32_t> unassigned = seed_order;  // kept in seed order
  std::uint32_t pass = 0;

  const auto add = [&](std::uint32_t x) {
    pass_of[x] = pass;
    unassigned.erase(std::find(unassigned.begin(), unassigned.end(), x));
    for (std::uint32_t i = inc.edge_offset[x]; i < inc.edge_offset[x + 1]; ++i) {
      const std::uint32_t e = inc.edge_index[i];
      if (touched[e]) continue;  // its other clusters already count it
      touched[e] = 1;
      touched_list.push_back(e);
      const ClusterHyperedge& h = inc.hyperedges[e];
      for (int j = 0; j < h.size(); ++j) {
        const std::uint32_t y = h.clusters[j];
        if (pass_of[y] != ClusterHyperedge::kNone) continue;
        if (gain[y] == 0) gained_list.push_back(y);
        gain[y] += h.weight;
      }
    }
  };

  while (!unassigned.empty()) {
    add(unassigned.front());
    for (int filled = 1; filled < per_pass && !unassigned.empty(); ++filled) {
      // Scanning in seed order makes the first maximum the tie-break winner.
      std::uint32_t best = unassigned.front();
      for (std::uint32_t y : unassigned)
        if (gain[y] > gain[best]) best = y;
      add(best);
    }
    for (std::uint32_t e : touched_list) touched[e] = 0;
    for (std::uint32_t y : gained_list) gain[y] = 0;
    touched_list.clear();
    gained_list.clear();
    ++pass;
  }
  return groups_from_pass_of(pass_of);
}

SuperClusters group_greedy(const SuperClusterInput& input) {
  return group_greedy(cluster_incidence(input), input.per_pass);
}

}  // namespace cpca
