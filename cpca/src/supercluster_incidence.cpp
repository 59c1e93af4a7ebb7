#include "cpca/supercluster_incidence.h"

#include <algorithm>
#include <map>
#include <utility>

namespace cpca {

ClusterIncidence cluster_incidence(const SuperClusterInput& input) {
  ClusterIncidence inc;
  inc.cluster_count = input.cluster_count;
  inc.triangle_count = input.triangles.size();
  const std::size_t k_count = std::size_t(input.cluster_count);
  inc.vertex_count.assign(k_count, 0);
  for (std::uint32_t k : input.cluster_of) ++inc.vertex_count[k];

  // Ordered map: hyperedge ids, and so every later tie-break, do not depend on hashing.
  std::map<std::array<std::uint32_t, 3>, std::uint32_t> weight_of;
  for (const TriangleIndices& t : input.triangles) {
    std::array<std::uint32_t, 3> c = {input.cluster_of[t[0]], input.cluster_of[t[1]],
                                      input.cluster_of[t[2]]};
    std::sort(c.begin(), c.end());
    const auto end = std::unique(c.begin(), c.end());
    if (end - c.begin() == 1) {
      ++inc.single_cluster_triangles;
      continue;
    }
    if (end - c.begin() == 2) c[2] = ClusterHyperedge::kNone;
    ++weight_of[c];
  }
  inc.hyperedges.reserve(weight_of.size());
  for (const auto& [clusters, weight] : weight_of) inc.hyperedges.push_back({clusters, weight});

  inc.edge_offset.assign(k_count + 1, 0);
  for (const ClusterHyperedge& h : inc.hyperedges)
    for (int i = 0; i < h.size(); ++i) ++inc.edge_offset[h.clusters[i] + 1];
  for (std::size_t k = 0; k < k_count; ++k) inc.edge_offset[k + 1] += inc.edge_offset[k];
  inc.edge_index.resize(inc.edge_offset.back());
  std::vector<std::uint32_t> fill(inc.edge_offset.begin(), inc.edge_offset.end() - 1);
  for (std::uint32_t e = 0; e < inc.hyperedges.size(); ++e) {
    const ClusterHyperedge& h = inc.hyperedges[e];
    for (int i = 0; i < h.size(); ++i) inc.edge_index[fill[h.clusters[i]]++] = e;
  }

  std::map<std::pair<std::uint32_t, std::uint32_t>, std::uint32_t> pair_weight;
  for (const ClusterHyperedge& h : inc.hyperedges) {
    const std::uint32_t w = h.size() == 2 ? 2 * h.weight : h.weight;
    for (int i = 0; i < h.size(); ++i)
      for (int j = 0; j < h.size(); ++j)
        if (i != j) pair_weight[{h.clusters[i], h.clusters[j]}] += w;
  }
  inc.neighbor_offset.assign(k_count + 1, 0);
  for (const auto& [pair, w] : pair_weight) {
    ++inc.neighbor_offset[pair.first + 1];
    inc.neighbor.push_back(pair.second);  // the map's order groups rows by pair.first
    inc.neighbor_weight.push_back(w);
  }
  for (std::size_t k = 0; k < k_count; ++k) inc.neighbor_offset[k + 1] += inc.neighbor_offset[k];
  return inc;
}

std::uint64_t triangles_drawn(const ClusterIncidence& incidence,
                              const std::vector<std::uint32_t>& pass_of) {
  std::uint64_t drawn = incidence.single_cluster_triangles;
  for (const ClusterHyperedge& h : incidence.hyperedges)
    drawn += std::uint64_t(h.weight) * std::uint64_t(distinct_passes(h, pass_of));
  return drawn;
}

SuperClusters groups_from_pass_of(const std::vector<std::uint32_t>& pass_of) {
  std::uint32_t passes = 0;
  for (std::uint32_t p : pass_of) passes = std::max(passes, p + 1);
  std::vector<std::vector<std::uint32_t>> members(passes);
  for (std::uint32_t k = 0; k < pass_of.size(); ++k) members[pass_of[k]].push_back(k);
  SuperClusters groups;
  groups.pass_of.resize(pass_of.size());
  for (auto& m : members) {
    if (m.empty()) continue;
    for (std::uint32_t k : m) groups.pass_of[k] = std::uint32_t(groups.passes.size());
    groups.passes.push_back(std::move(m));
  }
  return groups;
}

}  // namespace cpca
