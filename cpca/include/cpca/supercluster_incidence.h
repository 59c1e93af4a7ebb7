// cpca/supercluster_incidence.h: what super-cluster selection needs to know about a mesh,
// reduced from triangles to clusters.
//
// A triangle whose vertices all lie in one cluster is drawn once by every grouping, so only
// the triangles spanning 2 or 3 clusters matter. Triangles with the same set of clusters are
// interchangeable, so they are merged into one weighted hyperedge: the exact draw count of a
// grouping is then
//   single_cluster_triangles + sum over hyperedges h of weight(h) * distinct passes of h,
// which costs O(hyperedges) instead of O(triangles) (on a 256-cluster bunny, ~2k vs 70k).
#pragma once

#include "cpca/supercluster_strategy.h"

#include <array>
#include <cstdint>
#include <vector>

namespace cpca {

struct ClusterHyperedge {
  std::array<std::uint32_t, 3> clusters;  // distinct, ascending; clusters[2] == kNone for 2
  std::uint32_t weight = 0;               // triangles with exactly this cluster set
  static constexpr std::uint32_t kNone = ~0u;
  int size() const { return clusters[2] == kNone ? 2 : 3; }
};

struct ClusterIncidence {
  int cluster_count = 0;
  std::uint64_t triangle_count = 0;
  std::uint64_t single_cluster_triangles = 0;
  std::vector<std::uint32_t> vertex_count;  // vertices per cluster (the thesis's "most data")
  std::vector<ClusterHyperedge> hyperedges;
  // Hyperedges of cluster k: edge_index[edge_offset[k] .. edge_offset[k + 1]).
  std::vector<std::uint32_t> edge_offset;
  std::vector<std::uint32_t> edge_index;
  // Cluster-adjacency graph in CSR form (both directions, no self loops), weighted for a
  // graph partitioner: a 2-cluster triangle adds 2 to its pair, a 3-cluster triangle 1 to
  // each of its 3 pairs. Cutting a 2-cluster triangle costs one extra draw (cut weight 2);
  // a 3-cluster one costs 1 or 2 extra draws (cut weight 2 or 3), the closest a graph gets.
  std::vector<std::uint32_t> neighbor_offset;
  std::vector<std::uint32_t> neighbor;
  std::vector<std::uint32_t> neighbor_weight;
};

// Builds the incidence of a validated input (see validate()).
ClusterIncidence cluster_incidence(const SuperClusterInput& input);

// Distinct passes among a hyperedge's clusters under pass_of.
inline int distinct_passes(const ClusterHyperedge& h, const std::vector<std::uint32_t>& pass_of) {
  const std::uint32_t a = pass_of[h.clusters[0]], b = pass_of[h.clusters[1]];
  if (h.clusters[2] == ClusterHyperedge::kNone) return a == b ? 1 : 2;
  const std::uint32_t c = pass_of[h.clusters[2]];
  return 1 + int(a != b) + int(c != a && c != b);
}

// Exact triangles drawn over all passes under pass_of (one entry per cluster); equals
// overdraw(...).triangles_drawn for the same grouping.
std::uint64_t triangles_drawn(const ClusterIncidence& incidence,
                              const std::vector<std::uint32_t>& pass_of);

// SuperClusters from pass_of, dropping empty passes and renumbering the rest in order.
SuperClusters groups_from_pass_of(const std::vector<std::uint32_t>& pass_of);

}  // namespace cpca
